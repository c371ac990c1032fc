; tt-mating: an arrange-up problem in PDDL 2.1 for the domain arrange-up (arrange-up-domain.pddl).
; Units: inches and degrees. Written by arrange_up.io.pddl.write_pddl_problem.
; description: Two T-shaped parts pushed together until they interlock. The TT mating
;   rearrangement problem of thesis ch. 4 (Figures 2-16(c,d), 4-13(c,d) and 4-18; Table 4.2's
;   "TT mating" row): two identical non-convex T's start on the table (+-0.5 in, +-5 deg), the
;   second turned upside down, and the goal is relative. Each T is 1 in thick, 3 in wide and 3
;   in tall. In the goal the upside-down T2 slides in from the right: its stem fills the 1 x 2
;   in notch between T1's stem and the right arm of T1's cross bar, and T1's stem rests on T2's
;   cross bar, so each T's stem sits in the other's notch (the pair is symmetric under a half
;   turn) and they touch along 4 in of edge without overlapping. The paddle is "fairly long"
;   (§4.2.2): we chose 5.0 x 0.15 in, longer than the mated pair is wide (4 in), so one push can
;   drive both parts. The robot may place and pick one fixture (a 2.0 x 0.5 in bar). Workspace:
;   a 12 x 12 in table without walls; a part pushed off it makes an outcome invalid. Action
;   uncertainty (+-0.05 in, +-3 deg) applies to every action (push approach poses and fixture
;   places). Goal tolerance +-0.2 in, +-10 deg in T1's frame is our choice (interlocking parts
;   align each other).
(define (problem tt-mating)
  (:domain arrange-up)
  (:objects
    T1 - tee
    T2 - tee
    paddle - paddle-long
    bar - short-bar
  )
  (:init
    ; the table, 12 x 12 in; walls: none
    (= (table-width) 12) (= (table-depth) 12)
    ; action noise (half-widths) and domain parameter ranges
    (= (place-dx) 0.05) (= (place-dy) 0.05) (= (place-dtheta) 3)
    (= (push-dx) 0.05) (= (push-dy) 0.05) (= (push-dtheta) 3)
    (= (friction-min) 0.5) (= (friction-max) 0.6)
    (= (part-density-min) 0.1) (= (part-density-max) 0.15)
    (= (manipulator-density-min) 0.35) (= (manipulator-density-max) 0.45)
    ; objects on the table at the start: nominal pose and uncertainty
    (on-table T1) (= (x T1) 3.5) (= (y T1) 8) (= (theta T1) 0)
      (= (dx T1) 0.5) (= (dy T1) 0.5) (= (dtheta T1) 5)
    (on-table T2) (= (x T2) 8.5) (= (y T2) 4) (= (theta T2) 180)
      (= (dx T2) 0.5) (= (dy T2) 0.5) (= (dtheta T2) 5)
  )
  (:goal (and
    (on-table T1)
    (on-table T2)
    (>= (rel-x T2 T1) 0.8) (<= (rel-x T2 T1) 1.2)
    (>= (rel-y T2 T1) (- 2)) (<= (rel-y T2 T1) (- 1.6))
    (>= (rel-theta T2 T1) 170) (<= (rel-theta T2 T1) 190)
    ; fixtures that start off the table end off it (a fence put down is picked up)
    (not (on-table bar))
  ))
)

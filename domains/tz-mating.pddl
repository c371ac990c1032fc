; tz-mating: an arrange-up problem in PDDL 2.1 for the domain arrange-up (arrange-up-domain.pddl).
; Units: inches and degrees. Written by arrange_up.io.pddl.write_pddl_problem.
; description: A T-shaped and a Z-shaped part pushed together until they interlock. The TZ
;   mating rearrangement problem of thesis ch. 4 (Figures 2-16(a,b), 4-2 to 4-11 and 4-13(a,b);
;   Table 4.2's "TZ mating" row): two non-convex parts start on the table with small uncertainty
;   (+-0.05 in, +-1 deg) and the goal is relative (Figure 4-2(b): "the rotation and position of
;   the mated objects are not specified"). Both parts are 1 in thick: the T is 3 in wide and 3
;   in tall, the Z a Z-tetromino of 1-inch squares (3 x 2 in). In the goal the Z, standing
;   upright, fills the 1 x 2 in notch between the T's stem and the right arm of its cross bar
;   and hooks around the end of that arm, touching the T along 4 in of edge without overlapping
;   it. The Z starts already turned upright, so pushes need only translate it; it can slide into
;   the notch from the right. The paddle is "of medium length" (§4.2.2; "short" in §4.1): we
;   chose 3.0 x 0.15 in, as long as the T's cross bar. The robot may place and pick one fixture
;   (a 2.0 x 0.5 in bar, the "short rectangular bar" of Figure 4-8). Workspace: a 12 x 12 in
;   table without walls; a part pushed off it makes an outcome invalid (Figure 4-11). Action
;   uncertainty (+-0.05 in, +-3 deg) applies to every action (push approach poses and fixture
;   places). Goal tolerance +-0.2 in, +-10 deg in the T's frame is our choice (interlocking
;   parts align each other).
(define (problem tz-mating)
  (:domain arrange-up)
  (:objects
    T - tee
    Z - zed
    paddle - paddle-medium
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
    (on-table T) (= (x T) 3.5) (= (y T) 8) (= (theta T) 0)
      (= (dx T) 0.05) (= (dy T) 0.05) (= (dtheta T) 1)
    (on-table Z) (= (x Z) 8.5) (= (y Z) 4) (= (theta Z) 90)
      (= (dx Z) 0.05) (= (dy Z) 0.05) (= (dtheta Z) 1)
  )
  (:goal (and
    (on-table T)
    (on-table Z)
    (>= (rel-x Z T) 1.3) (<= (rel-x Z T) 1.7)
    (>= (rel-y Z T) (- 0.6)) (<= (rel-y Z T) (- 0.2))
    (>= (rel-theta Z T) 80) (<= (rel-theta Z T) 100)
    ; fixtures that start off the table end off it (a fence put down is picked up)
    (not (on-table bar))
  ))
)

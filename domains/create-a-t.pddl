; create-a-t: an arrange-up problem in PDDL 2.1 for the domain arrange-up (arrange-up-domain.pddl).
; Units: inches and degrees. Written by arrange_up.io.pddl.write_pddl_problem.
; description: Two rectangular bars pushed together into a T. The Create a T rearrangement
;   problem of thesis ch. 4 (Figures 2-15(c,d) and 4-12(c,d); Table 4.2's "Create a T" row), by
;   far the hardest of the chapter's problems: both bars start on the table (+-0.35 in, +-5
;   deg), far apart, and the goal is relative: the stem (a 1 x 3 in bar, standing) must end
;   centred under the top bar (a 3 x 1 in bar, lying), touching it, wherever the top bar ends.
;   The robot may place and pick one fixture (a 2.0 x 0.5 in bar) and pushes with the 2.5 x 0.15
;   in real-robot paddle (the thesis gives no size for this problem). Workspace: a 12 x 12 in
;   table without walls, as in chapter 4, where a part pushed off the table makes an outcome
;   invalid. Action uncertainty (+-0.05 in, +-5 deg) applies to every action (push approach
;   poses and fixture places). Goal tolerance +-0.25 in, +-10 deg (in the top bar's frame) is
;   our choice: two flat faces do not self-align, so it is a little looser than the mating
;   problems'.
(define (problem create-a-t)
  (:domain arrange-up)
  (:objects
    top - block-3x1
    stem - block-1x3
    paddle - paddle-short
    bar - short-bar
  )
  (:init
    ; the table, 12 x 12 in; walls: none
    (= (table-width) 12) (= (table-depth) 12)
    ; action noise (half-widths) and domain parameter ranges
    (= (place-dx) 0.05) (= (place-dy) 0.05) (= (place-dtheta) 5)
    (= (push-dx) 0.05) (= (push-dy) 0.05) (= (push-dtheta) 5)
    (= (friction-min) 0.5) (= (friction-max) 0.6)
    (= (part-density-min) 0.1) (= (part-density-max) 0.15)
    (= (manipulator-density-min) 0.35) (= (manipulator-density-max) 0.45)
    ; objects on the table at the start: nominal pose and uncertainty
    (on-table top) (= (x top) 4) (= (y top) 8.5) (= (theta top) 0)
      (= (dx top) 0.35) (= (dy top) 0.35) (= (dtheta top) 5)
    (on-table stem) (= (x stem) 8.5) (= (y stem) 4) (= (theta stem) 0)
      (= (dx stem) 0.35) (= (dy stem) 0.35) (= (dtheta stem) 5)
  )
  (:goal (and
    (on-table top)
    (on-table stem)
    (>= (rel-x stem top) (- 0.25)) (<= (rel-x stem top) 0.25)
    (>= (rel-y stem top) (- 2.25)) (<= (rel-y stem top) (- 1.75))
    (>= (rel-theta stem top) (- 10)) (<= (rel-theta stem top) 10)
    ; fixtures that start off the table end off it (a fence put down is picked up)
    (not (on-table bar))
  ))
)

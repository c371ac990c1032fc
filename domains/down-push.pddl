; down-push: an arrange-up problem in PDDL 2.1 for the domain arrange-up (arrange-up-domain.pddl).
; Units: inches and degrees. Written by arrange_up.io.pddl.write_pddl_problem.
; description: One block in the middle of the table pushed straight down 3 inches. The Down
;   Push rearrangement problem of thesis ch. 4 (Figures 2-15(a,b), 4-12(a,b) and 4-15; Table
;   4.2's "Down Push" row): the part starts on the table with a large initial uncertainty (+-1.0
;   in, +-15 deg), the goal is absolute, and the robot may place and pick one fixture (a 2.0 x
;   0.5 in bar, "a short rectangular bar" of Figure 4-8) to push against. Workspace: a 12 x 12
;   in table without walls, as in chapter 4, where a part pushed off the table makes an outcome
;   invalid (Figure 4-11). The paddle is the 2.5 x 0.15 in real-robot paddle (the thesis gives
;   no size for this problem). Action uncertainty (+-0.2 in, +-1 deg) applies to every action:
;   to the paddle's approach pose of a push and to where a placed fixture lands. Goal tolerance
;   +-1.25 in across, +-0.5 in along the push, +-15 deg is our choice: the goal is about how far
;   down the block went, and a downward push cannot narrow the +-1.0 in initial spread across it
;   (the thesis reports the nominal plan "nearly perfect", which only a tolerance wider than
;   that spread allows); along the push the paddle sets the block's position, uncertain by +-0.2
;   in.
(define (problem down-push)
  (:domain arrange-up)
  (:objects
    block - block-1x1
    paddle - paddle-short
    bar - short-bar
  )
  (:init
    ; the table, 12 x 12 in; walls: none
    (= (table-width) 12) (= (table-depth) 12)
    ; action noise (half-widths) and domain parameter ranges
    (= (place-dx) 0.2) (= (place-dy) 0.2) (= (place-dtheta) 1)
    (= (push-dx) 0.2) (= (push-dy) 0.2) (= (push-dtheta) 1)
    (= (friction-min) 0.5) (= (friction-max) 0.6)
    (= (part-density-min) 0.1) (= (part-density-max) 0.15)
    (= (manipulator-density-min) 0.55) (= (manipulator-density-max) 0.6)
    ; objects on the table at the start: nominal pose and uncertainty
    (on-table block) (= (x block) 6) (= (y block) 6) (= (theta block) 0)
      (= (dx block) 1) (= (dy block) 1) (= (dtheta block) 15)
  )
  (:goal (and
    (on-table block)
    (>= (x block) 4.75) (<= (x block) 7.25)
    (>= (y block) 2.5) (<= (y block) 3.5)
    (>= (theta block) (- 15)) (<= (theta block) 15)
    ; fixtures that start off the table end off it (a fence put down is picked up)
    (not (on-table bar))
  ))
)

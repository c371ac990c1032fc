; blocks-4: an arrange-up problem in PDDL 2.1 for the domain arrange-up (arrange-up-domain.pddl).
; Units: inches and degrees. Written by arrange_up.io.pddl.write_pddl_problem.
; description: Four blocks as a 2x2 square in the lower-right corner. The 4-block construction
;   problem (thesis ch. 3, Table 3.1 '4 Blocks', Figures 3-6 and 3-7; one of the five real-robot
;   assemblies of §3.3); also the example of the problem format. Block world of thesis ch. 3 on
;   the real-robot set-up of §2.4.2: a 10 x 5 in board walled on all four sides, 1-inch wooden
;   blocks that start off the table and are placed by the robot (place uncertainty +-0.2 in,
;   +-15 deg, measured in Figure 2-21), and the 2.5 x 0.15 in paddle. The goal is built into the
;   corner against the walls so that pushes against them make the blocks' poses certain; every
;   block is flush with its neighbours and the walls. Goal tolerance is the real-robot
;   experiments' +-0.2 in (with +-15 deg). Push uncertainty +-0.05 in, +-3 deg is our choice
;   (the thesis states none for ch. 3); friction is the range the push model was trained on (mu
;   in [0.25, 0.55], §3.2); the density ranges are Table 4.2's nominal ones.
(define (problem blocks-4)
  (:domain arrange-up)
  (:objects
    A - block-1x1
    B - block-1x1
    C - block-1x1
    D - block-1x1
    paddle - paddle-short
  )
  (:init
    ; the table, 10 x 5 in; walls: left, right, bottom, top
    (= (table-width) 10) (= (table-depth) 5)
    (wall-left) (wall-right) (wall-bottom) (wall-top)
    ; action noise (half-widths) and domain parameter ranges
    (= (place-dx) 0.2) (= (place-dy) 0.2) (= (place-dtheta) 15)
    (= (push-dx) 0.05) (= (push-dy) 0.05) (= (push-dtheta) 3)
    (= (friction-min) 0.25) (= (friction-max) 0.55)
    (= (part-density-min) 0.1) (= (part-density-max) 0.15)
    (= (manipulator-density-min) 0.35) (= (manipulator-density-max) 0.45)
  )
  (:goal (and
    (on-table A)
    (>= (x A) 9.3) (<= (x A) 9.7)
    (>= (y A) 0.3) (<= (y A) 0.7)
    (>= (theta A) (- 15)) (<= (theta A) 15)
    (on-table B)
    (>= (x B) 8.3) (<= (x B) 8.7)
    (>= (y B) 0.3) (<= (y B) 0.7)
    (>= (theta B) (- 15)) (<= (theta B) 15)
    (on-table C)
    (>= (x C) 9.3) (<= (x C) 9.7)
    (>= (y C) 1.3) (<= (y C) 1.7)
    (>= (theta C) (- 15)) (<= (theta C) 15)
    (on-table D)
    (>= (x D) 8.3) (<= (x D) 8.7)
    (>= (y D) 1.3) (<= (y D) 1.7)
    (>= (theta D) (- 15)) (<= (theta D) 15)
  ))
)

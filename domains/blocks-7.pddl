; blocks-7: an arrange-up problem in PDDL 2.1 for the domain arrange-up (arrange-up-domain.pddl).
; Units: inches and degrees. Written by arrange_up.io.pddl.write_pddl_problem.
; description: Seven blocks as a staircase in the lower-right corner. Four blocks lie along
;   the bottom wall (A-D from the corner) and three on top of them against the right wall (E-G).
;   The 7-block construction problem (thesis ch. 3, Table 3.1 '7 Blocks', Figures 3-6 and 3-7,
;   and the real-robot run of Figure 3-12). Block world of thesis ch. 3 on the real-robot set-up
;   of §2.4.2: a 10 x 5 in board walled on all four sides, 1-inch wooden blocks that start off
;   the table and are placed by the robot (place uncertainty +-0.2 in, +-15 deg, measured in
;   Figure 2-21), and the 2.5 x 0.15 in paddle. The goal is built into the corner against the
;   walls so that pushes against them make the blocks' poses certain; every block is flush with
;   its neighbours and the walls. Goal tolerance is the real-robot experiments' +-0.2 in (with
;   +-15 deg). Push uncertainty +-0.05 in, +-3 deg is our choice (the thesis states none for ch.
;   3); friction is the range the push model was trained on (mu in [0.25, 0.55], §3.2); the
;   density ranges are Table 4.2's nominal ones.
(define (problem blocks-7)
  (:domain arrange-up)
  (:objects
    A - block-1x1
    B - block-1x1
    C - block-1x1
    D - block-1x1
    E - block-1x1
    F - block-1x1
    G - block-1x1
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
    (>= (x C) 7.3) (<= (x C) 7.7)
    (>= (y C) 0.3) (<= (y C) 0.7)
    (>= (theta C) (- 15)) (<= (theta C) 15)
    (on-table D)
    (>= (x D) 6.3) (<= (x D) 6.7)
    (>= (y D) 0.3) (<= (y D) 0.7)
    (>= (theta D) (- 15)) (<= (theta D) 15)
    (on-table E)
    (>= (x E) 9.3) (<= (x E) 9.7)
    (>= (y E) 1.3) (<= (y E) 1.7)
    (>= (theta E) (- 15)) (<= (theta E) 15)
    (on-table F)
    (>= (x F) 8.3) (<= (x F) 8.7)
    (>= (y F) 1.3) (<= (y F) 1.7)
    (>= (theta F) (- 15)) (<= (theta F) 15)
    (on-table G)
    (>= (x G) 7.3) (<= (x G) 7.7)
    (>= (y G) 1.3) (<= (y G) 1.7)
    (>= (theta G) (- 15)) (<= (theta G) 15)
  ))
)

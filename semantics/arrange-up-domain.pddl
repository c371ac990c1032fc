; The shared action vocabulary of arrange-up problems (PDDL 2.1 with typing and numeric fluents).
;
; Every .pddl problem of arrange-up is a problem of this domain. PDDL 2.1 cannot give an action
; real-valued parameters or effects computed by a physics simulation, so this file declares what
; PDDL can: the types, the functions and predicates that describe a problem, and the three
; actions with their symbolic preconditions. What a place or push does to the poses is defined
; by arrange-up's transition semantics (arrange_up.up.compile.to_up builds the unified-planning
; model with real parameters and simulated effects).
;
; Units: lengths in inches, angles in degrees. Generated from semantics/shapes.yaml by
; arrange_up.io.pddl.domain_pddl_text(); a test keeps this file and the catalogue in step.
(define (domain arrange-up)
  (:requirements :strips :typing :negative-preconditions :numeric-fluents)

  (:types
    ; movable objects can be on or off the table; obstacles are fixed on it
    movable obstacle - object
    placeable manipulator - movable
    part fixture - placeable
    ; shape types (semantics/shapes.yaml): each gives an object its kind and its geometry
    block-1x1 block-3x1 block-1x3 tee zed - part
    paddle-short paddle-medium paddle-long - manipulator
    short-bar - fixture
    pillar - obstacle
  )

  (:predicates
    (on-table ?o)   ; in :init, the object starts on the table
    (wall-left) (wall-right) (wall-bottom) (wall-top)   ; rigid walls along the table's edges
  )

  (:functions
    ; nominal pose (x, y in inches; theta in degrees) of an object on the table at the start,
    ; or of an obstacle; the pose refers to the shape's area centroid
    (x ?o) (y ?o) (theta ?o)
    ; half-widths of the initial uncertainty: the pose lies in x +- dx, y +- dy, theta +- dtheta
    (dx ?o - movable) (dy ?o - movable) (dtheta ?o - movable)
    ; pose of part ?p in the frame of part ?r (relative goals)
    (rel-x ?p - part ?r - part) (rel-y ?p - part ?r - part) (rel-theta ?p - part ?r - part)
    ; the table [0, table-width] x [0, table-depth], inches
    (table-width) (table-depth)
    ; action noise: a place lands within the target +- these half-widths, a push's approach pose
    ; within the commanded one +- these
    (place-dx) (place-dy) (place-dtheta) (push-dx) (push-dy) (push-dtheta)
    ; domain parameters, drawn uniformly per action (densities in mass per square inch)
    (friction-min) (friction-max)
    (part-density-min) (part-density-max)
    (manipulator-density-min) (manipulator-density-max)
  )

  ; place ?o at a pose (real parameters x, y, theta in the arrange-up model): the object must be
  ; off the table. Where it lands, and what it touches, is up to the semantics.
  (:action place
    :parameters (?o - placeable)
    :precondition (not (on-table ?o))
    :effect (on-table ?o))

  ; push with ?m from an approach pose over a distance (real parameters in the arrange-up
  ; model): the manipulator is put down, driven perpendicular to its long side and lifted off
  ; again, so it must start off the table. Its effect on the poses is the semantics' physics.
  (:action push
    :parameters (?m - manipulator)
    :precondition (not (on-table ?m))
    :effect (and))

  ; pick ?o off the table (no uncertainty)
  (:action pick
    :parameters (?o - movable)
    :precondition (on-table ?o)
    :effect (not (on-table ?o)))
)

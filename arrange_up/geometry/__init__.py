"""Plane geometry: SE(2) poses, polygons and convex decomposition, belief shadows, boxes and
collision tests. numpy and shapely; no physics, no planning.

Modules: :mod:`~arrange_up.geometry.se2` (poses, rotations, transforms),
:mod:`~arrange_up.geometry.polygons` (validity, areas, centroids, convexity, penetration depth),
:mod:`~arrange_up.geometry.decomposition` (convex pieces), :mod:`~arrange_up.geometry.shadows`
(belief shadows), :mod:`~arrange_up.geometry.boxes` (boxes, walls),
:mod:`~arrange_up.geometry.shapes` (footprints; and every name of the former single module),
:mod:`~arrange_up.geometry.collision` (tests on a problem's table). Only ``collision`` imports
from the rest of ``arrange_up`` (the model), so every other room may depend on this one.

Conventions (the contract every function here keeps):

* The world frame is the table's: ``x`` to the right, ``y`` up, angles in radians,
  counter-clockwise positive.
* A :data:`Polygon` is a tuple of ``(x, y)`` float pairs, counter-clockwise (positive signed
  area), with no repeated closing vertex. Functions that *accept* polygons take any sequence of
  pairs (lists, tuples, ``(N, 2)`` arrays) and either orientation unless they say otherwise;
  functions that *return* polygons return CCW tuples of Python floats.
* A shape is a sequence of convex CCW polygons (its *parts*) in the object's own frame; a
  :data:`Pose` ``(x, y, theta)`` places the object frame in the world: an object point ``p``
  lands at ``R(theta) @ p + (x, y)``.
* A pose interval is a pose plus half-widths ``(dx, dy, dtheta)``: the true pose is anywhere in
  ``[x-dx, x+dx] x [y-dy, y+dy] x [theta-dtheta, theta+dtheta]``.
* A :data:`Box` is ``(xmin, ymin, xmax, ymax)``.
* A *belief shadow* (thesis "Reliably arranging objects", §2.1.2) is a region containing the
  shape at **every** pose of an interval, rotation included. Both shadows here are
  conservative by construction: :func:`shadow_box` is the exact smallest such box, and
  :func:`shadow_hull` is a convex polygon containing the exact swept region (it over-approximates
  the arcs traced by rotating vertices by at most ``r * (1 / cos(max_step / 2) - 1)``).
  The thesis's formula, which places the shape only at the interval's end angles, can miss a
  corner that swings past an axis direction mid-interval; ours cannot.

Functions that need valid input check it and raise :class:`ValueError` (self-intersecting
polygons, negative half-widths, unknown wall names, ...); nothing here silently repairs input.
Low-level helpers (areas, transforms, box predicates) do no checking, for speed.
"""

from arrange_up.geometry.shapes import *  # noqa: F403  (the public names of the former module arrange_up.geometry)

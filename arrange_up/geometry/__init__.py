"""Plane geometry: polygons and convex decomposition, SE(2) poses, belief shadows, boxes and
collision tests. shapely and numpy; no physics, no planning."""

from arrange_up.geometry.shapes import *  # noqa: F403  (the public names of the former module arrange_up.geometry)

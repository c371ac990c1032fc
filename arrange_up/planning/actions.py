"""Action generators and preconditions (thesis §2.1.3, §2.2.1).

The action space is continuous; :class:`ActionGenerator` proposes a small discrete set per
belief, asking one generator per kind of action (:mod:`arrange_up.planning.generators`) in a
fixed order:

1. **places** of the goal parts off the table (:mod:`~arrange_up.planning.generators.places`);
2. **places of fences** (:mod:`arrange_up.planning.fences`): where a goal part needs one (its
   goal is tighter along an axis than a free push can stop it, and the table has no wall the
   goal holds it against there), places of a fixture at the part's goal face; nothing for a
   problem whose parts need no fence (every shipped problem);
3. **pushes** of the parts on the table (:mod:`~arrange_up.planning.generators.pushes`: where
   the manipulator stands, :mod:`~arrange_up.planning.generators.approach`; how far it
   travels, :mod:`~arrange_up.planning.generators.distances`, with the wall trains, mating,
   detours and the compliant controller's stall in their own modules);
4. **picks** of the fixtures and manipulators on the table
   (:mod:`~arrange_up.planning.generators.picks`).

Preconditions are tested on belief shadows (:mod:`arrange_up.geometry.collision`): a placed
object's shadow (target +- place uncertainty) and a manipulator's approach shadow (approach
pose +- push uncertainty) must not touch any shadow of an object on the table, a wall or an
obstacle, and a placed object's shadow must lie on the table.
"""

from __future__ import annotations

from arrange_up.belief.states import IntervalBelief
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.model.world import Action, Pick, Place, Push
from arrange_up.planning.fences import Fences
from arrange_up.planning.generators.approach import Approach
from arrange_up.planning.generators.common import PushOptions
from arrange_up.planning.generators.detours import Detours
from arrange_up.planning.generators.distances import PushDistances
from arrange_up.planning.generators.mating_pushes import MatingPushes
from arrange_up.planning.generators.picks import PickGenerator
from arrange_up.planning.generators.places import PlaceGenerator
from arrange_up.planning.generators.pushes import PushGenerator, Routes
from arrange_up.planning.generators.stall import PushStall
from arrange_up.planning.generators.targets import GoalTargets
from arrange_up.planning.generators.wall_trains import held_by_wall, wall_trains
from arrange_up.planning.mating import Mates
from arrange_up.planning.obstacles import Obstacles


class ActionGenerator:
    """Proposes the candidate actions of a belief (see the module docstring).

    The keyword options are :class:`~arrange_up.planning.generators.common.PushOptions`', and
    ``place_rings``: offer places on rings farther out where a part's place grid has none clear
    (:mod:`~arrange_up.planning.generators.places`)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        checker: CollisionChecker,
        *,
        unclipped_pushes: bool = False,
        settled_wall_pushes: bool = False,
        compressed_wall_pushes: bool = False,
        solve_distances: bool = True,
        clearance_pushes: bool = True,
        place_rings: bool = True,
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.options = options = PushOptions(
            unclipped_pushes=unclipped_pushes,
            settled_wall_pushes=settled_wall_pushes,
            compressed_wall_pushes=compressed_wall_pushes,
            solve_distances=solve_distances,
            clearance_pushes=clearance_pushes,
        )
        self.place_unc = problem.uncertainty.place
        self.push_unc = problem.uncertainty.push
        self.wall_trains = wall_trains(problem, checker)
        self.fences = Fences(problem, checker, held_by_wall(problem, self.wall_trains))
        self.obstacles = Obstacles(checker)
        self.mates = Mates(problem)
        self.targets = GoalTargets(problem, self.mates)
        self.stall = PushStall(problem, checker, options)
        detours = Detours(problem, checker, self.obstacles, self.targets)
        mating = MatingPushes(problem, self.mates, self.targets, self.stall, options)
        distances = PushDistances(
            problem,
            checker,
            options,
            targets=self.targets,
            trains=self.wall_trains,
            stall=self.stall,
            fences=self.fences,
            obstacles=self.obstacles,
            mates=self.mates,
            mating=mating,
            detours=detours,
        )
        self.place_generator = PlaceGenerator(
            problem, checker, self.targets, with_rings=place_rings
        )
        self.push_generator = PushGenerator(
            problem,
            checker,
            options,
            targets=self.targets,
            stall=self.stall,
            detours=detours,
            distances=distances,
            approach=Approach(problem, checker, options, self.fences),
            fences=self.fences,
            obstacles=self.obstacles,
            mates=self.mates,
        )
        self.pick_generator = PickGenerator(problem, self.fences, self.targets)

    def candidates(self, belief: IntervalBelief) -> list[Action]:
        """Every applicable candidate action of ``belief`` (preconditions hold), in a fixed
        order: places of parts, places of fences (:mod:`arrange_up.planning.fences`), then
        pushes, then picks."""
        places = self.places(belief)
        routes = self.fence_routes(belief)
        fences = list(dict.fromkeys(a for options in routes.values() for a in options))
        return [*places, *fences, *self.pushes(belief, places, routes), *self.picks(belief)]

    def fence_routes(self, belief: IntervalBelief) -> Routes:
        """The fence places of ``belief``, keyed by the ``(part, axis, sign)`` of the push
        that would press the part against them (empty unless a goal part needs a fence)."""
        if not self.fences.needs:
            return {}
        return self.fences.placements(belief, [(n, iv.center, iv.half) for n, iv in belief.objects])

    def place_target(self, name: str, belief: IntervalBelief) -> Pose | None:
        """Where ``name`` should end according to the goal, given ``belief``
        (:meth:`~arrange_up.planning.generators.targets.GoalTargets.place_target`)."""
        return self.targets.place_target(name, belief)

    def places(self, belief: IntervalBelief, only: str | None = None) -> list[Place]:
        """Place candidates of every goal part off the table (or of ``only``)."""
        return self.place_generator.places(belief, only)

    def place_poses(self, belief: IntervalBelief, name: str) -> list[Pose]:
        """Candidate place poses of ``name`` that fit the table, walls and obstacles
        (:meth:`~arrange_up.planning.generators.places.PlaceGenerator.place_poses`)."""
        return self.place_generator.place_poses(belief, name)

    def pushes(
        self,
        belief: IntervalBelief,
        places: list[Place] | None = None,
        routes: Routes | None = None,
    ) -> list[Push]:
        """The push candidates of ``belief``; ``places`` and ``routes``, its place candidates
        and fence routes if the caller has them already (:meth:`candidates`), save computing
        them again."""
        routes = self.fence_routes(belief) if routes is None else routes
        placeable = {a.obj for a in (self.places(belief) if places is None else places)}
        return self.push_generator.pushes(belief, placeable, routes)

    def picks(self, belief: IntervalBelief) -> list[Pick]:
        """Picks of the fixtures and manipulators on the table
        (:mod:`~arrange_up.planning.generators.picks`)."""
        return self.pick_generator.picks(belief)

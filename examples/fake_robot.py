"""A robot bridge in a few lines: closed-loop execution on a fake robot.

    python examples/fake_robot.py

A real bridge (ROS 2, a vendor SDK) implements the same one method, ``execute(action,
index)``: command the motion, wait for it to finish, and return what was sensed as an
``Observation`` (inches and radians, in the problem's table frame), raising
``ExecutionFailed`` when the motion could not be carried out. Here the "robot" is a
kinematic fake: it moves the paddle as commanded, reports the encoder pose with a little
noise, and keeps no part poses of its own, so it stands for the arm alone (a real bridge's
encoders). The parts' physics is the simulated executor's, which this fake drives as the
world; only the adapter's shape matters.
"""

from __future__ import annotations

from arrange_up.evaluation.outcomes import ACTION_FAILED, Failure
from arrange_up.execution import (
    ClosedLoop,
    ClosedLoopSettings,
    ExecutionFailed,
    Observation,
    SimulatedExecutor,
    sensor_for,
)
from arrange_up.io.domains import load
from arrange_up.model.world import Action, Pick, Place, Push
from arrange_up.planning.planner import plan


class FakeRobot:
    """The adapter: translate an action to motion commands, the encoders to an observation."""

    def __init__(self, world: SimulatedExecutor) -> None:
        self.world = world  # stands for the real table
        self.log: list[str] = []

    def execute(self, action: Action, index: int) -> Observation:
        # 1. the motion command a bridge would send (a ROS 2 action goal, say)
        if isinstance(action, Place):
            self.log.append(f"{index}: pick {action.obj} from the tray, place at {action.pose}")
        elif isinstance(action, Push):
            self.log.append(
                f"{index}: lower {action.manipulator} at {action.pose}, "
                f"push {action.distance:.2f} in, lift"
            )
        elif isinstance(action, Pick):
            self.log.append(f"{index}: pick {action.obj} off the table")
        # 2. wait for the result; a controller error becomes ExecutionFailed
        try:
            observation = self.world.execute(action, index)
        except ExecutionFailed as error:
            raise ExecutionFailed(
                Failure(ACTION_FAILED, index, f"robot: {error.failure.reason or 'failed'}")
            ) from error
        # 3. the encoders' reading after a push (None after a place: nothing sensed)
        return Observation(paddle=observation.paddle)


def main() -> None:
    problem = load("blocks-2")
    first = plan(problem, semantics="particles", particles=5, max_nodes=300)
    sensor = sensor_for(problem, "paddle")
    robot = FakeRobot(SimulatedExecutor(problem, sensor, seed=0, episode=0))
    loop = ClosedLoop(problem, first.actions or (), sensor, ClosedLoopSettings(filter_particles=16))
    outcome = loop.run(robot)
    print("\n".join(robot.log))
    print(
        f"stopped: {outcome.stopped}; {len(outcome.replans)} replans, "
        f"{len(outcome.model_failures)} model failures; the posterior satisfies the goal "
        f"with probability {outcome.estimate:.2f}"
    )


if __name__ == "__main__":
    main()

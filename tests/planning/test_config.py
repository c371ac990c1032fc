"""PlanConfig: one frozen value configures a planning run; its checks are written once."""

from __future__ import annotations

import pytest

from arrange_up.io.domains import load
from arrange_up.parallel import RunnerConfig
from arrange_up.planning.config import DEFAULT_MAX_NODES, PlanConfig, SearchConfig
from arrange_up.planning.planner import plan


def test_flat_options_land_in_their_group():
    config = PlanConfig.of(semantics="deterministic", max_nodes=7, workers=2, agenda=False)
    assert config.semantics == "deterministic"
    assert config.search == SearchConfig(max_nodes=7, agenda=False)
    assert config.runner == RunnerConfig(workers=2)
    assert PlanConfig.of(config, seed=3) == PlanConfig(
        semantics="deterministic", seed=3, search=config.search, runner=config.runner
    )


def test_an_unknown_option_is_a_type_error():
    with pytest.raises(TypeError, match="unknown planning option 'particle'"):
        PlanConfig.of(particle=3)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"semantics": "quantum"}, "unknown semantics 'quantum'"),
        ({"particles": 0}, "particles must be a positive integer, got 0"),
        ({"particles": True}, "particles must be a positive integer, got True"),
        ({"seed": -1}, "seed must be a non-negative integer, got -1"),
        ({"validate": -2}, "validate must be a non-negative integer, got -2"),
        ({"max_nodes": 0}, "max_nodes must be a positive integer, got 0"),
        ({"heuristic": "oracle"}, "unknown heuristic 'oracle'"),
        ({"backend": "cloud"}, "unknown backend 'cloud'"),
        ({"scheduler": "tcp://x:1"}, "a scheduler address needs the dask backend"),
    ],
)
def test_bad_values_fail_when_the_config_is_made(options, message):
    with pytest.raises(ValueError, match=message):
        PlanConfig.of(**options)


def test_the_node_limit_is_the_configs_else_the_problems_else_the_default():
    assert SearchConfig(max_nodes=9).node_limit(100) == 9
    assert SearchConfig().node_limit(100) == 100
    assert SearchConfig().node_limit(None) == DEFAULT_MAX_NODES


def test_a_config_plans_as_the_same_flat_options_do():
    problem = load("blocks-2")
    config = PlanConfig(semantics="deterministic", search=SearchConfig(max_nodes=200))
    by_config = plan(problem, config)
    by_options = plan(problem, semantics="deterministic", max_nodes=200)
    assert by_config.solved and by_config.actions == by_options.actions
    assert by_config.stats == {**by_options.stats, "elapsed": by_config.stats["elapsed"]}

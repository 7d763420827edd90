"""The failure paths run: the engine's errors say what failed and where."""

from __future__ import annotations

import numpy as np
import pytest

from microimpact.presets import WALL_1990
from microimpact.solvers.engine import EngineError, solve_normal, solve_normal_many


def test_engine_step_limit_is_an_engine_error_naming_the_speed():
    with pytest.raises(EngineError, match=r"normal speed 1.0 m/s: step limit reached after 5 steps"):
        solve_normal(WALL_1990, 1.0, max_steps=5)


def test_batch_engine_step_limit_names_the_first_failing_speed():
    with pytest.raises(EngineError, match=r"normal speed 1.0 m/s: step limit reached"):
        solve_normal_many(WALL_1990, np.array([1.0, 2.0]), max_steps=5)


def test_engine_error_is_a_runtime_error_the_cli_turns_into_a_message():
    # the CLI reports RuntimeError subclasses in one line with exit status 2
    assert issubclass(EngineError, RuntimeError)


@pytest.mark.parametrize("speed", [1e-100, 1e-60, 1e-35])
def test_speeds_below_the_engines_resolution_are_refused_not_answered_wrongly(speed):
    """Below v_n T/X = 1e-30 the incident energy is round-off against the contact well; the engine
    once returned rebounds with e_n = -2.5 there. Now: a ValueError that says why."""
    import microimpact as mi

    with pytest.raises(ValueError, match="below what the engine resolves"):
        mi.simulate_impact(WALL_1990, speed)
    with pytest.raises(ValueError, match="below what the engine resolves"):
        solve_normal_many(WALL_1990, np.array([1.0, speed]))


def test_just_above_the_resolution_limit_the_sphere_is_captured():
    import microimpact as mi

    v = 2e-30 * WALL_1990.length_scale / WALL_1990.time_scale
    res = mi.simulate_impact(WALL_1990, v)
    assert res.outcome == "capture" and res.e_n == 0.0

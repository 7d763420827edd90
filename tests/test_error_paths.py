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

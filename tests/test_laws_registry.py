"""The registry of contact laws (microimpact.model.laws): one declaration per law, the support
matrix derived from it, and every combination it allows run through the library's entry points."""

import math

import numpy as np
import pytest

from microimpact.model import laws
from microimpact.model.contact import SUB_MODELS
from microimpact.solvers import METHODS, SUPPORTED_SUB_MODELS, check_sub_models
from microimpact.solvers.impact import simulate_impact, simulate_many

COMBINATIONS = list(laws.combinations())


def test_the_registry_names_the_contacts_choices_and_derives_the_support_matrix():
    assert laws.fields() == tuple(SUB_MODELS)
    for field in laws.fields():
        assert laws.names(field) == SUB_MODELS[field]
        for name in laws.names(field):
            assert laws.get(name, field).field == field and laws.get(name, field).name == name
    assert SUPPORTED_SUB_MODELS == {m: laws.supported(m) for m in METHODS}
    # the paper's method covers the paper's model only, and every law runs on the engine
    assert {f: v for f, v in laws.supported("rkg").items()} == {f: (v[0],) for f, v in SUB_MODELS.items()}
    assert laws.supported("engine") == dict(SUB_MODELS)


@pytest.mark.parametrize("args, message", [(("hertz",), "normal_model must be one of ring, jkr, dmt, jkr_force, got 'hertz'"),
                                           (("ring", "colour"), "field must be one of normal_model, ")])
def test_an_unknown_law_is_refused_in_one_line(args, message):
    with pytest.raises(ValueError, match="^" + message.replace("(", r"\(")) as info:
        laws.get(*args)
    assert "\n" not in str(info.value)


def test_the_combinations_cover_every_declared_law_and_their_methods_are_what_the_solvers_accept():
    for field in laws.fields():
        seen = {c.choices[field] for c in COMBINATIONS}
        assert seen == set(laws.names(field)), field
    assert len({tuple(c.choices.items()) + (c.contact.adhesion_line_force,) for c in COMBINATIONS}) == len(COMBINATIONS)
    for c in COMBINATIONS:
        for method in METHODS:
            if method in c.methods:
                check_sub_models(c.contact, method)
            else:
                with pytest.raises(ValueError, match=f"is not covered by method={method!r}; use method="):
                    check_sub_models(c.contact, method)


def _one_of_each():
    """Combinations that between them take every declared law at least once (a few, for the fast suite)."""
    picked, missing = [], {(f, n) for f in laws.fields() for n in laws.names(f)}
    for c in COMBINATIONS:
        new = {(f, n) for f, n in c.choices.items()} & missing
        if new:
            picked.append(c)
            missing -= new
    assert not missing
    return picked


def _check_every_entry_point(combination):
    """A result from every method the combination's laws declare; a one-line refusal from the others."""
    contact = combination.contact
    for method in METHODS:
        if method not in combination.methods:
            with pytest.raises(ValueError) as info:
                simulate_impact(contact, 1.0, 30.0, method=method)
            assert "\n" not in str(info.value) and f"method={method!r}" in str(info.value)
            continue
        try:
            res = simulate_impact(contact, 1.0, 30.0, omega=(0.0, 0.0, 1e4), method=method)
        except ValueError as exc:  # a documented refusal: one line naming what and why
            assert "\n" not in str(exc) and method == "rkg" and "capture" in str(exc)
            continue
        assert res.outcome in ("rebound", "capture") and math.isfinite(res.e_n) and 0.0 <= res.e_n <= 1.0
    batch = simulate_many(contact, [0.3, 3.0], [0.0, 45.0])
    assert np.isfinite(batch["e_n"].values).all()


@pytest.mark.parametrize("index", range(len(_one_of_each())))
def test_every_declared_law_runs_through_the_library(index):
    _check_every_entry_point(_one_of_each()[index])


@pytest.mark.slow
@pytest.mark.parametrize("index", range(len(COMBINATIONS)))
def test_every_combination_runs_through_the_library(index):
    _check_every_entry_point(COMBINATIONS[index])

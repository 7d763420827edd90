"""The mutation check's table (tests/mutation_check.py) still matches the code, checked without
running it: running the check takes tens of minutes and is a documented study, so a physics line
reworded without its mutation being updated would otherwise go unnoticed until the next full run."""

from __future__ import annotations

import json

from mutation_check import KILLERS, MUTATIONS, REPO


def test_every_mutation_still_applies_to_exactly_one_line():
    stale = []
    for file, original, mutation, what in MUTATIONS:
        count = (REPO / "toolkit" / "microimpact" / file).read_text().count(original)
        if count != 1 or mutation == original:
            stale.append(f"{file}: {what} (original text found {count} times)")
    assert not stale, "update MUTATIONS in tests/mutation_check.py:\n" + "\n".join(stale)


def test_every_killer_file_exists():
    assert [k for k in KILLERS if not (REPO / k).is_file()] == []


def test_the_committed_check_killed_every_mutation_it_ran():
    """docs/mutations.json (the last full run) ran the table's first entries (the table grows at its
    end; a mutation added later is checked alone when it is added, with --select) and killed each."""
    committed = json.loads((REPO / "docs" / "mutations.json").read_text())
    ran = [(r["file"], r["what"]) for r in committed["results"]]
    assert ran and ran == [(m[0], m[3]) for m in MUTATIONS[:len(ran)]]
    assert committed["killed"] == committed["mutations"] == len(ran)
    assert all(r["killed"] for r in committed["results"])
    assert committed["tests"] == KILLERS

"""The input files a command names (for its outputs' provenance) and the measured impacts of one material pair."""

from __future__ import annotations

from microimpact._commands.common import UsageError
from microimpact.io.impacts import material_pairs, read_impacts, select_material_pair
from microimpact.io.materials import default_materials_path, read_materials
from microimpact.io.paths import check_input_file


def input_files(args) -> dict:
    """The input files a command reads (option name -> path), each an existing readable file; the
    bundled materials config counts as an input when no --config is given."""
    given = {"data file": getattr(args, "data", None), "--config": args.config, "--fit": getattr(args, "fit", None)}
    inputs = {name: check_input_file(name, path) for name, path in given.items() if path is not None}
    if args.config is None:
        inputs["the bundled materials config"] = default_materials_path()
    return inputs


def impacts_for_pair(args):
    """Read the impact CSV (validated against the materials config) and pick the material pair."""
    data = check_input_file("data file", args.data)
    config = check_input_file("--config", args.config) if args.config else default_materials_path()
    pairs = read_materials(config)
    table = read_impacts(data, materials=pairs)
    labels = material_pairs(table)
    name = args.material_pair or (labels[0] if len(labels) == 1 else None)
    if name is None:
        raise UsageError(f"{data}: give --material-pair (the file has {'pairs ' + ', '.join(labels) if labels else 'no material_pair column'})")
    if name not in pairs:
        raise UsageError(f"unknown material pair {name!r}; known pairs in {config}: {', '.join(pairs)}")
    try:  # unlabelled rows belong to the named pair
        return select_material_pair(table, name, default=name), pairs[name]
    except ValueError as e:
        raise UsageError(str(e)) from None

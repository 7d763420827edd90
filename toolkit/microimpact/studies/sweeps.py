"""Config-driven parameter sweeps: the initial-condition cases of Table 2 and any grid like them.

Cheng, Brach & Dunn (2002), "Three-Dimensional Modeling of Microsphere Contact/Impact with Smooth,
Flat Surfaces", Aerosol Sci. Technol. 36(11):1081-1093, doi:10.1080/02786820290092221, Table 2 and
Figs. 7-14.

A *sweep spec* is a plain dict (so that it can come from a YAML or JSON config). Its keys are the
inputs of :func:`microimpact.solvers.impact.simulate_many`:

============== ========= =====================================================================
key            units     meaning
============== ========= =====================================================================
speed          m/s       magnitude v of the incident velocity (required)
incidence_deg  degree    incidence angle alpha from the surface normal, in [0, 90)
azimuth_deg    degree    azimuth theta of the tangential velocity, from t towards t'
omega_n        rad/s     initial spin about the normal n
omega_t        rad/s     initial spin about t
omega_tp       rad/s     initial spin about t'
friction       1         Coulomb friction coefficient f (default: the contact's)
============== ========= =====================================================================

Each value is one of

* a number: the quantity is fixed (a 0-d variable in the result, no dimension);
* a list of numbers: explicit values, swept (one dimension, even for a single value);
* a range dict ``{"start": a, "stop": b, "num": n, "spacing": "linear" | "log"}`` (n points,
  both ends included; "linear" is the default) or ``{"start": a, "stop": b, "step": h}``
  (a, a + h, ... up to and including b within 1e-9 h).

Numbers may also be given as strings ("2.9e5"): PyYAML reads ``2.9e5`` without a dot in the
mantissa and a sign in the exponent as a string. A spec may carry a ``description`` (text) and,
when it was made by :func:`split_spec`, a ``chunk`` entry; any other key is an error.

The result of :func:`run_sweep` has one dimension per swept quantity, named after its spec key
(in the order of the table above), with a coordinate of the same name.
"""

from __future__ import annotations

import copy
import json
import math
import numbers
from collections.abc import Mapping, Sequence
from datetime import datetime, timezone

import numpy as np
import xarray as xr

from microimpact import __version__
from microimpact.analysis.fit_result import DampingFit
from microimpact.dynamics.nonlinear import capture_velocity
from microimpact.io.files import CONVENTIONS, restore_label_coordinates, write_netcdf
from microimpact._runtime.progress import progress_bar, wants_progress
from microimpact.io.variables import attributes
from microimpact.model.contact import PAPER_REFERENCE
from microimpact.model.parameters import TABLE2_CASES, table2_case
from microimpact.solvers import DEFAULT_RTOL, Deadline
from microimpact.solvers.impact import simulate_many

__all__ = [
    "TABLE2_CASES",
    "case_spec",
    "SWEEP_INPUTS",
    "SweepSpecError",
    "resolve_spec",
    "run_sweep",
    "split_spec",
    "combine_sweeps",
    "save_sweep",
    "load_sweep",
    "restitution_curves",
    "PAPER_REFERENCE",
]

#: the sweep inputs in dimension order (units and long names: microimpact.io.variables)
SWEEP_INPUTS: tuple[str, ...] = ("speed", "incidence_deg", "azimuth_deg", "omega_n", "omega_t", "omega_tp", "friction")

_VALID = {
    "speed": (lambda a: np.all(a > 0.0), "> 0 m/s"),
    "incidence_deg": (lambda a: np.all((a >= 0.0) & (a < 90.0)), "in [0, 90) deg"),
    "friction": (lambda a: np.all(a >= 0.0), ">= 0"),
}
_META_KEYS = ("description", "chunk")



class SweepSpecError(ValueError):
    """A sweep spec is malformed; the message names the key and says what is accepted.

    Examples
    --------
    >>> resolve_spec({"speed": "fast"})
    Traceback (most recent call last):
    ...
    microimpact.studies.sweeps.SweepSpecError: spec['speed']: the value must be a number, got the text 'fast'
    """


# ----------------------------------------------------------------------------- spec handling
def _number(key: str, what: str, value) -> float:
    if isinstance(value, bool) or value is None:
        raise SweepSpecError(f"spec[{key!r}]: {what} must be a number, got {value!r}")
    if isinstance(value, numbers.Real):
        x = float(value)
    elif isinstance(value, str):
        try:
            x = float(value)
        except ValueError:
            raise SweepSpecError(f"spec[{key!r}]: {what} must be a number, got the text {value!r}") from None
    else:
        raise SweepSpecError(f"spec[{key!r}]: {what} must be a number, got {type(value).__name__} {value!r}")
    if not math.isfinite(x):
        raise SweepSpecError(f"spec[{key!r}]: {what} must be finite, got {value!r}")
    return x


def _range_values(key: str, r: Mapping) -> np.ndarray:
    allowed = {"start", "stop", "num", "spacing", "step"}
    unknown = sorted(set(r) - allowed)
    if unknown:
        raise SweepSpecError(
            f"spec[{key!r}]: unknown range field(s) {unknown}; a range is "
            "{start, stop, num[, spacing]} or {start, stop, step}"
        )
    for field in ("start", "stop"):
        if field not in r:
            raise SweepSpecError(f"spec[{key!r}]: range needs {field!r} (got fields {sorted(r)})")
    start = _number(key, "'start'", r["start"])
    stop = _number(key, "'stop'", r["stop"])
    if ("num" in r) == ("step" in r):
        raise SweepSpecError(f"spec[{key!r}]: give exactly one of 'num' and 'step' in a range")
    if "step" in r:
        if "spacing" in r and r["spacing"] != "linear":
            raise SweepSpecError(f"spec[{key!r}]: 'step' only makes linear ranges; use 'num' with spacing 'log'")
        step = _number(key, "'step'", r["step"])
        if step <= 0.0 or stop < start:
            raise SweepSpecError(f"spec[{key!r}]: a step range needs step > 0 and stop >= start, got {dict(r)}")
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        return start + step * np.arange(n)
    num = r["num"]
    if isinstance(num, bool) or not isinstance(num, numbers.Integral) or num < 1:
        raise SweepSpecError(f"spec[{key!r}]: 'num' must be an integer >= 1, got {num!r}")
    spacing = r.get("spacing", "linear")
    if spacing == "linear":
        return np.linspace(start, stop, int(num))
    if spacing == "log":
        if start <= 0.0 or stop <= 0.0:
            raise SweepSpecError(f"spec[{key!r}]: spacing 'log' needs start and stop > 0, got {start!r}, {stop!r}")
        return np.geomspace(start, stop, int(num))
    raise SweepSpecError(f"spec[{key!r}]: 'spacing' must be 'linear' or 'log', got {spacing!r}")


def _values(key: str, value):
    """float for a fixed quantity, 1-D float array for a swept one."""
    if isinstance(value, Mapping):
        arr = _range_values(key, value)
    elif isinstance(value, (np.ndarray, Sequence)) and not isinstance(value, str):
        arr = np.asarray(value, dtype=object)
        if arr.ndim != 1 or arr.size == 0:
            raise SweepSpecError(f"spec[{key!r}]: a list of values must be flat and non-empty, got {value!r}")
        arr = np.array([_number(key, f"value {i}", v) for i, v in enumerate(arr)], dtype=float)
        if np.unique(arr).size != arr.size:
            raise SweepSpecError(f"spec[{key!r}]: values must be distinct (they become a coordinate), got {value!r}")
    else:
        arr = np.asarray(_number(key, "the value", value))
    check = _VALID.get(key)
    if check is not None and not check[0](arr):
        raise SweepSpecError(f"spec[{key!r}]: every value must be {check[1]}, got {arr.tolist()!r}")
    return float(arr) if arr.ndim == 0 else arr


def resolve_spec(spec: Mapping) -> dict[str, float | np.ndarray]:
    """Validate a sweep spec and expand it.

    Parameters
    ----------
    spec : mapping
        See the module docstring.

    Returns
    -------
    dict
        Spec key -> float (fixed) or 1-D numpy array (swept), for the keys given, in the order of
        :data:`SWEEP_INPUTS`.

    Raises
    ------
    SweepSpecError
        (a ValueError) naming the offending key and what it accepts.

    Examples
    --------
    A list becomes an array (a swept dimension), a number stays fixed:

    >>> resolve_spec({"speed": [1, 2], "incidence_deg": 30})
    {'speed': array([1., 2.]), 'incidence_deg': 30.0}
    >>> resolve_spec({"sped": 1})
    Traceback (most recent call last):
    ...
    microimpact.studies.sweeps.SweepSpecError: unknown spec key(s) ['sped']; accepted: ...
    """
    if not isinstance(spec, Mapping):
        raise SweepSpecError(f"a sweep spec must be a mapping (dict), got {type(spec).__name__}")
    unknown = sorted(k for k in spec if k not in SWEEP_INPUTS and k not in _META_KEYS)
    if unknown:
        raise SweepSpecError(
            f"unknown spec key(s) {unknown}; accepted: {', '.join(SWEEP_INPUTS)} (and {', '.join(_META_KEYS)})"
        )
    if "speed" not in spec:
        raise SweepSpecError("spec['speed'] is required (a number, a list or a range of speeds in m/s)")
    if "description" in spec and not isinstance(spec["description"], str):
        raise SweepSpecError(f"spec['description'] must be text, got {spec['description']!r}")
    return {k: _values(k, spec[k]) for k in SWEEP_INPUTS if k in spec}


def _plain(obj, unknown=None):
    """A JSON-able copy (numpy scalars and arrays become Python numbers and lists).

    ``unknown``, if given, converts any other object that is not a str, int, float, bool or None
    (e.g. ``str``); by default such objects are kept as they are.
    """
    if isinstance(obj, Mapping):
        return {str(k): _plain(v, unknown) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (list, tuple)):
        return [_plain(v, unknown) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    if unknown is None or isinstance(obj, (str, int, float, bool, type(None))):
        return obj
    return unknown(obj)


def _spec_json(spec: Mapping) -> str:
    return json.dumps(_plain(spec), sort_keys=True)


# ----------------------------------------------------------------------------- running
def _now() -> str:
    return datetime.now(timezone.utc).replace(microsecond=0).isoformat().replace("+00:00", "Z")


def case_spec(case: str, overrides: Mapping | None = None) -> dict:
    """The grid of Table 2 case ``case`` with some of its keys replaced.

    Parameters
    ----------
    case : str
        "2.1" ... "2.5" (:data:`microimpact.model.parameters.TABLE2_CASES`).
    overrides : mapping, optional
        Spec keys (module docstring) that replace the case's; the description then says so.

    Raises
    ------
    ValueError
        For an unknown case (the message lists the known ones).

    Examples
    --------
    Case 2.1 as Table 2 gives it, and with the speeds replaced (the description says so):

    >>> case_spec("2.1")["incidence_deg"]
    {'start': 0.0, 'stop': 30.0, 'step': 5.0}
    >>> case_spec("2.1", {"speed": [1.0, 2.0]})["description"].endswith("(grid changed by the configuration: speed)")
    True
    """
    spec = table2_case(case)
    changed = {k: v for k, v in (overrides or {}).items() if k != "description"}
    if changed:
        spec.update(changed)
        spec["description"] += f" (grid changed by the configuration: {', '.join(sorted(changed))})"
    return spec


def run_sweep(contact, spec: Mapping | None = None, *, case: str | None = None, rtol: float = DEFAULT_RTOL,
              institution: str | None = None, capture_speed: bool = True, progress=None,
              time_budget: float | None = None) -> xr.Dataset:
    """Simulate every impact of a sweep grid with :func:`microimpact.solvers.impact.simulate_many`.

    Parameters
    ----------
    contact : Contact
        Contact parameters (Table 1 row 2 is :data:`microimpact.presets.WALL_1990`).
    spec : mapping, optional
        The grid (module docstring). Default: ``TABLE2_CASES[case]``.
    case : str, optional
        Label of the case, e.g. "2.1"; recorded in the attributes and the title.
    rtol : float
        Relative tolerance of the normal solves. [-]
    institution : str, optional
        Written to the ``institution`` attribute when given.
    capture_speed : bool
        Also compute the normal capture velocity of the contact (bisection on the outcome with
        the same solver tolerance, :func:`microimpact.dynamics.nonlinear.capture_velocity`) and store it as
        the 0-d variable ``capture_normal_speed``; the figures mark it.
    progress : bool, optional
        Draw a progress bar on stderr (:func:`microimpact._runtime.progress.progress_bar`) when stderr is
        a terminal; the speeds are then solved in blocks to advance it (same values as one batch).
        Default: silent.
    time_budget : float or Deadline, optional
        Wall-clock budget; None: no limit. With a budget the speeds are solved in blocks (as for
        the progress bar) and the budget is checked after each block and after the capture
        velocity (one :func:`~microimpact.solvers.impact.simulate_many` is a compiled call that
        cannot stop midway); past it, TimeBudgetExceeded, giving the speeds done. [s]

    Returns
    -------
    xarray.Dataset
        One dimension per swept quantity (named after its spec key, with a coordinate of that
        name), in the order speed, incidence_deg, azimuth_deg, omega_n, omega_t, omega_tp,
        friction. Fixed inputs are 0-d variables. Result variables as in
        :data:`microimpact.solvers.impact.RESULT_VARIABLES` (outcome, e_n, mu_t, mu_tp, K_L, K_t,
        velocity_out_*, omega_out_*, contact_time, max_penetration, slip_ended, friction_impulse,
        dissipated_energy), each with ``units`` and ``long_name``; mu_t and mu_tp are NaN for a
        captured impact. CF-1.10 global attributes, the contact parameters (``contact_*``) and
        the spec as JSON (``sweep_spec``).

    Examples
    --------
    Four normal impacts of the 1990 wall sphere: the two slow ones are captured (e_n = 0), at or
    below the capture speed the sweep reports:

    >>> from microimpact.presets import WALL_1990
    >>> ds = run_sweep(WALL_1990, {"speed": [0.5, 1.0, 2.0, 4.0]})
    >>> ds["e_n"].values.round(4).tolist(), round(float(ds["capture_normal_speed"]), 3)
    ([0.0, 0.0, 0.4425, 0.64], 1.449)
    """
    deadline = Deadline.start(time_budget, f"sweep {case}" if case else "sweep")

    if spec is None:
        if case is None or case not in TABLE2_CASES:
            raise SweepSpecError(f"give a spec, or a case among {sorted(TABLE2_CASES)}; got case={case!r}")
        spec = TABLE2_CASES[case]
    inputs = _grid_inputs(resolve_spec(spec))
    label = f"Table 2 case {case}" if case in TABLE2_CASES else (f"case {case}" if case else "parameter sweep")
    n_speeds = inputs["speed"].size if isinstance(inputs["speed"], xr.DataArray) else 1
    steps = n_speeds + int(capture_speed)
    with progress_bar(steps, f"sweep {label}", progress) as advance:
        advance = deadline.ticking(advance, steps, f"steps ({n_speeds} speeds, then the capture velocity)"
                                   if capture_speed else "speeds")
        ds = _simulate_grid(contact, inputs, rtol, advance, in_blocks=wants_progress(progress) or deadline.limited)
        if capture_speed:
            v_capture = capture_velocity(contact, solver_rtol=rtol)
            advance(1)
    dims = [k for k in SWEEP_INPUTS if k in inputs and isinstance(inputs[k], xr.DataArray)]
    ds = ds.transpose(*dims)
    for key in SWEEP_INPUTS:
        attrs = attributes(key)
        if key in dims:
            ds[key].attrs = attrs
        else:  # fixed input: a 0-d variable instead of a constant array over the grid
            fixed = float(inputs[key]) if key in inputs else (contact.friction if key == "friction" else 0.0)
            ds[key] = xr.DataArray(fixed, attrs=attrs)
    if capture_speed:
        ds["capture_normal_speed"] = xr.DataArray(
            v_capture,
            attrs={"units": "m s-1", "long_name": "normal impact speed below which the sphere is captured"},
        )
    order = [k for k in SWEEP_INPUTS if k not in dims] + [k for k in ds.data_vars if k not in SWEEP_INPUTS]
    ds = ds[order]
    ds.attrs = _sweep_attributes(ds, dims, spec, case, label, rtol, institution)
    return ds


def _sweep_attributes(ds: xr.Dataset, dims: list, spec: Mapping, case, label: str, rtol: float, institution) -> dict:
    """The global attributes of :func:`run_sweep`'s dataset ``ds`` (swept along ``dims``): CF-1.10's,
    the case and its description, the contact and solver of :func:`~microimpact.solvers.impact.simulate_many`
    (``ds.attrs``), the spec as JSON and the swept dimensions."""
    n = int(np.prod([ds.sizes[d] for d in dims])) if dims else 1
    attrs = {
        "Conventions": CONVENTIONS,
        "title": f"Microsphere impact sweep: {label} (Cheng, Brach & Dunn 2002 model)",
        "source": f"microimpact {__version__}",
        "history": f"{_now()} microimpact.studies.sweeps.run_sweep(case={case!r}, rtol={rtol:g}): "
        f"{n} impacts over {', '.join(f'{d}[{ds.sizes[d]}]' for d in dims) or 'a single point'}",
        "references": PAPER_REFERENCE,
        "comment": "mu_t, mu_tp are NaN for captured impacts (no rebound); K_L, K_t of a captured "
        "sphere use its final state (it may roll on, no rolling resistance).",
    }
    if institution:
        attrs["institution"] = institution
    attrs["case"] = case if case is not None else ""
    attrs["case_description"] = str(spec.get("description", ""))
    attrs.update(ds.attrs)  # contact_* and solver, from simulate_many
    attrs["sweep_spec"] = _spec_json(spec)
    attrs["sweep_dims"] = " ".join(dims)
    return attrs


def _grid_inputs(values: Mapping) -> dict:
    """simulate_many inputs of a resolved spec: a float per fixed quantity, a DataArray along its own
    dimension per swept one."""
    return {key: float(val) if np.ndim(val) == 0 else xr.DataArray(val, dims=(key,), coords={key: val}, name=key)
            for key, val in values.items()}


#: blocks of speeds a sweep is solved in when it shows a progress bar
PROGRESS_BLOCKS = 20


def _simulate_grid(contact, inputs: Mapping, rtol: float, advance, *, in_blocks: bool = False) -> xr.Dataset:
    """simulate_many over the sweep grid ``inputs``; ``in_blocks``: along speed in up to
    :data:`PROGRESS_BLOCKS` blocks, calling ``advance(n)`` after each (every impact is solved on
    its own, so the values equal those of one batch; the test suite checks it)."""
    get = lambda k, default=0.0: inputs.get(k, default)  # noqa: E731

    def solve(speed):
        return simulate_many(contact, speed, get("incidence_deg"), get("azimuth_deg"),
                             omega=(get("omega_n"), get("omega_t"), get("omega_tp")),
                             friction=get("friction", None), rtol=rtol)

    speed = inputs["speed"]
    if not (in_blocks and isinstance(speed, xr.DataArray) and speed.size > 1):
        ds = solve(speed)
        advance(speed.size if isinstance(speed, xr.DataArray) else 1)
        return ds
    parts = []
    for block in np.array_split(np.arange(speed.size), min(speed.size, PROGRESS_BLOCKS)):
        parts.append(solve(speed.isel(speed=block)))
        advance(block.size)
    return xr.concat(parts, dim="speed", data_vars="minimal", coords="minimal", compat="override",
                     combine_attrs="override")


# ----------------------------------------------------------------------------- chunking
def split_spec(spec: Mapping, n_chunks: int, along: str = "speed") -> list[dict]:
    """Split a spec into ``n_chunks`` specs that together cover the same grid.

    Each chunk replaces the ``along`` entry by an explicit list of its share of the values
    (consecutive, sizes differing by at most one) and records ``chunk = {index, count, along,
    parent}`` so that :func:`combine_sweeps` can check completeness and restore the parent spec.

    Split along ``speed`` (the default) where possible: the chunks then solve disjoint sets of
    normal speeds (no repeated work) and the combined result is identical to an unchunked run in
    every variable. Along another dimension each chunk repeats the normal solves, and for captured
    impacts the tail integrals ``friction_impulse`` and ``dissipated_energy`` can differ slightly
    (the engine follows the tail only as far as the tangential outcomes of its batch need); all
    coefficients and final velocities are still identical.

    Raises
    ------
    SweepSpecError
        If ``along`` is not swept in ``spec`` or ``n_chunks`` is not in [1, number of values].

    Examples
    --------
    Two chunks of four speeds, each remembering its parent:

    >>> chunks = split_spec({"speed": [0.5, 1.0, 2.0, 4.0]}, 2)
    >>> [c["speed"] for c in chunks], chunks[1]["chunk"]["index"]
    ([[0.5, 1.0], [2.0, 4.0]], 1)
    """
    values = resolve_spec(spec)
    if along not in values or np.ndim(values[along]) == 0:
        swept = [k for k, v in values.items() if np.ndim(v) == 1]
        raise SweepSpecError(f"split_spec: {along!r} is not swept in this spec; swept keys: {swept}")
    n_values = values[along].size
    if isinstance(n_chunks, bool) or not isinstance(n_chunks, numbers.Integral) or not 1 <= n_chunks <= n_values:
        raise SweepSpecError(f"split_spec: n_chunks must be an integer in [1, {n_values}], got {n_chunks!r}")
    parent = _plain(spec)
    if "chunk" in parent:
        raise SweepSpecError("split_spec: this spec is already a chunk; split its parent instead")
    chunks = []
    for i, part in enumerate(np.array_split(values[along], int(n_chunks))):
        chunk = copy.deepcopy(parent)
        chunk[along] = part.tolist()
        chunk["chunk"] = {"index": i, "count": int(n_chunks), "along": along, "parent": parent}
        chunks.append(chunk)
    return chunks


def combine_sweeps(datasets: Sequence[xr.Dataset], along: str | None = None) -> xr.Dataset:
    """Gather sweep chunks (from :func:`split_spec` + :func:`run_sweep`) into one Dataset.

    Parameters
    ----------
    datasets : sequence of xarray.Dataset
        The chunks, in any order.
    along : str, optional
        Dimension to concatenate along. Default: read from the chunks' ``sweep_spec``.

    Returns
    -------
    xarray.Dataset
        Equal to a single :func:`run_sweep` of the parent spec (values, coordinates, attributes);
        ``sweep_spec`` is the parent spec and ``history`` gains a line for the combination.

    Raises
    ------
    ValueError
        If the chunks do not come from one split (different parent spec or contact parameters,
        missing or repeated chunks) or their other coordinates differ.

    Examples
    --------
    Two chunks, run apart and combined, give the unchunked sweep (split along the speed: every
    variable identical):

    >>> from microimpact.presets import WALL_1990
    >>> spec = {"speed": [0.5, 1.0, 2.0, 4.0]}
    >>> whole = run_sweep(WALL_1990, spec)
    >>> parts = [run_sweep(WALL_1990, chunk) for chunk in split_spec(spec, 2)]
    >>> float(abs(combine_sweeps(parts)["e_n"] - whole["e_n"]).max())
    0.0
    """
    datasets = list(datasets)
    if not datasets:
        raise ValueError("combine_sweeps: no datasets given")
    specs = [json.loads(ds.attrs.get("sweep_spec", "{}")) for ds in datasets]
    chunk_info = [s.get("chunk") for s in specs]
    parent = None
    if all(c is not None for c in chunk_info):
        parents = {json.dumps(c["parent"], sort_keys=True) for c in chunk_info}
        if len(parents) != 1:
            raise ValueError("combine_sweeps: the chunks come from different parent specs")
        alongs = {c["along"] for c in chunk_info}
        if along is not None and alongs != {along}:
            raise ValueError(f"combine_sweeps: chunks were split along {sorted(alongs)}, not {along!r}")
        along = alongs.pop()
        count = chunk_info[0]["count"]
        indices = sorted(c["index"] for c in chunk_info)
        if indices != list(range(count)):
            raise ValueError(f"combine_sweeps: expected chunks 0..{count - 1} once each, got indices {indices}")
        order = np.argsort([c["index"] for c in chunk_info])
        datasets = [datasets[i] for i in order]
        parent = chunk_info[0]["parent"]
    elif along is None:
        raise ValueError("combine_sweeps: the datasets carry no chunk record; say along which dimension to combine")
    for ds in datasets:
        if along not in ds.dims:
            raise ValueError(f"combine_sweeps: a dataset has no dimension {along!r} (dims {dict(ds.sizes)})")
    first = datasets[0]
    for i, ds in enumerate(datasets[1:], start=1):
        for key, value in first.attrs.items():
            if key.startswith("contact_") and ds.attrs.get(key) != value:
                raise ValueError(f"combine_sweeps: dataset {i} has {key}={ds.attrs.get(key)!r}, dataset 0 {value!r}")
    combined = xr.concat(datasets, dim=along, data_vars="minimal", coords="minimal", compat="equals",
                         join="exact", combine_attrs="override")
    for name, var in first.variables.items():  # concat may drop attrs of 0-d variables
        combined[name].attrs = dict(var.attrs)
    attrs = dict(first.attrs)
    if "normal_solves" in attrs:  # counts of work done add up over the chunks
        attrs["normal_solves"] = int(sum(int(ds.attrs.get("normal_solves", 0)) for ds in datasets))
    if parent is not None:
        attrs["sweep_spec"] = _spec_json(parent)
    dims = attrs.get("sweep_dims", "").split()
    n = int(np.prod([combined.sizes[d] for d in dims])) if dims else combined.sizes[along]
    attrs["history"] = (
        f"{_now()} microimpact.studies.sweeps.combine_sweeps: {len(datasets)} chunks along {along}, {n} impacts\n"
        + "\n".join(ds.attrs.get("history", "") for ds in datasets)
    )
    combined.attrs = attrs
    return combined.transpose(*[d for d in first.dims])


# ----------------------------------------------------------------------------- files
def save_sweep(ds: xr.Dataset, path):
    """Write a sweep to NetCDF-4 atomically with zlib compression (:func:`microimpact.io.files.write_netcdf`).

    Returns
    -------
    pathlib.Path

    Examples
    --------
    A round trip through a NetCDF file:

    >>> import tempfile, pathlib
    >>> from microimpact.presets import WALL_1990
    >>> ds = run_sweep(WALL_1990, {"speed": [2.0, 4.0]})
    >>> path = save_sweep(ds, pathlib.Path(tempfile.mkdtemp()) / "sweep.nc")
    >>> bool((load_sweep(path)["e_n"] == ds["e_n"]).all())
    True
    """
    return write_netcdf(ds, path)


def load_sweep(path) -> xr.Dataset:
    """Read a sweep written by :func:`save_sweep` into memory (file closed afterwards).

    Examples
    --------
    See :func:`save_sweep`; a file that is not a sweep is refused:

    >>> load_sweep("no_such_file.nc")
    Traceback (most recent call last):
    ...
    FileNotFoundError: ...
    """
    with xr.open_dataset(path, decode_timedelta=False) as ds:
        return restore_label_coordinates(ds.load())


# ----------------------------------------------------------------------------- model curves for figures
def restitution_curves(fit_dataset: xr.Dataset, speed=None, *, radius=None, rtol: float = DEFAULT_RTOL) -> xr.Dataset:
    """Model e_n(v_n) curves at the best fit of a damping fit, one per sphere radius (Fig. 3 lines).

    Parameters
    ----------
    fit_dataset : xarray.Dataset
        :meth:`microimpact.analysis.fitting.DampingFit.to_dataset` output.
    speed : spec value, optional
        Normal speeds (a list or a range dict as in a sweep spec). [m/s] Default: 60 log-spaced
        speeds spanning the data, widened by 20 % each way.
    radius : sequence of float, optional
        Radii. [m] Default: the distinct radii of the fitted points.
    rtol : float
        Relative tolerance of the normal solves. [-]

    Returns
    -------
    xarray.Dataset
        ``e_n`` and ``outcome`` on dims (``radius`` [m], ``speed`` [m/s], the normal speed).

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> path = write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    >>> fit = fit_damping(read_impacts(path), material, confidence_intervals=False).to_dataset()
    >>> curves = restitution_curves(fit, [1.0, 2.0, 5.0])
    >>> curves["e_n"].values.round(4).tolist()
    [[0.0, 0.4516, 0.672]]
    """

    fit = DampingFit.from_dataset(fit_dataset)
    v_data = np.asarray(fit_dataset["normal_speed"].values, dtype=float)
    if speed is None:
        speed = {"start": float(v_data.min()) / 1.2, "stop": float(v_data.max()) * 1.2, "num": 60, "spacing": "log"}
    speeds = np.atleast_1d(_values("speed", speed))
    radii = np.unique(fit_dataset["radius"].values) if radius is None else np.atleast_1d(np.asarray(radius, float))
    e_n, outcome = [], []
    for r in radii:
        res = simulate_many(fit.contact(float(r)), speeds, rtol=rtol)
        e_n.append(res["e_n"].values)
        outcome.append(res["outcome"].values)
    return xr.Dataset(
        {
            "e_n": (("radius", "speed"), np.array(e_n), attributes("e_n")),
            "outcome": (("radius", "speed"), np.array(outcome), attributes("outcome")),
        },
        coords={
            "radius": ("radius", radii, {"units": "m", "long_name": "sphere radius"}),
            "speed": ("speed", speeds, {"units": "m s-1", "long_name": "incident normal speed"}),
        },
        attrs={"title": "model e_n curves at the best-fit damping", "references": PAPER_REFERENCE},
    )


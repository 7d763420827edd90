"""The registry of contact laws: each law and sub-model declared once, with what it supports.

A :class:`SubModel` is one choice of a :class:`~microimpact.model.contact.Contact` field
(``normal_model``, ``tangential_model``, ...): its name, a one-line summary, the solver paths
(``simulate_impact(method=...)``) that cover it and the parameters it needs with the default each
documents. Selecting by name is :func:`get`; :func:`names` lists a field's choices;
:func:`combinations` enumerates every law x sub-model combination that a
:class:`~microimpact.model.contact.Contact` accepts, with those defaults.
:data:`microimpact.solvers.SUPPORTED_SUB_MODELS` (the support matrix the solvers check) is derived
from these declarations, not written beside them.

A :class:`RestitutionLaw` is a law fitted to measured e_n(v_n) (``microimpact fit --law NAME``) and
ranked by the model comparison: the paper's damped ring force, and the rate-independent
elastic-plastic laws that are not (yet) a Contact choice; :func:`restitution_laws` lists them,
:func:`restitution_law` looks one up.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType

from microimpact.model import contact as _contact
from microimpact.model.dem_rolling import DEM_ROLLING_MODELS
from microimpact.model.dem_tangential import DEM_TANGENTIAL_MODELS
from microimpact.model.dem_twisting import DEM_TWISTING_MODELS

__all__ = ["Combination", "RestitutionLaw", "SubModel", "combinations", "coupled_refusal", "fields", "get", "names",
           "restitution_law", "restitution_laws", "supported"]

#: every solver path, in the order of microimpact.solvers.METHODS
_METHODS = ("engine", "reference", "rkg")
_ALL, _SCIPY = _METHODS, ("engine", "reference")


@dataclass(frozen=True)
class SubModel:
    """One selectable law of a Contact field.

    Attributes
    ----------
    field : str
        The Contact field it is a choice of ("normal_model", ...).
    name : str
        Its name, as the field takes it.
    summary : str
        One line: what it is and where it is written.
    methods : tuple of str
        The solver paths (``simulate_impact(method=...)``) that cover it.
    parameters : Mapping of str to float
        The Contact fields it needs beside its name, with the default each documents (SI units);
        used by :func:`combinations`.
    coupled : bool
        For a normal or damping law: whether the engine's coupled solver (solvers.coupled)
        integrates it. For a tangential or friction law: whether it needs that solver (a
        tangential compliance or an adhesion-aware limit outside LAMMPS's laws). A combination
        that needs the coupled solver with a law it does not integrate runs on no path.
    """

    field: str
    name: str
    summary: str
    methods: tuple[str, ...]
    parameters: Mapping[str, float] = field(default_factory=dict)
    coupled: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))


def _dem(field_, name, summary, methods=("engine",), coupled=False, **parameters):
    return SubModel(field_, name, summary, methods, parameters, coupled)


_G = {"shear_modulus": 3e8}  # [Pa], the tests' and docs' Mindlin shear modulus of a polymer sphere
#: the declarations, by field; a field's first choice is its default (the paper's model)
_DECLARED: tuple[SubModel, ...] = (
    SubModel("normal_model", "ring", "the paper's adhesion ring force, Eqs. (4)-(6) (model.law)", _ALL, coupled=True),
    SubModel("normal_model", "jkr", "JKR adhesion, contact broken at the critical approach (model.adhesion_models)", _SCIPY),
    SubModel("normal_model", "dmt", "DMT adhesion (model.adhesion_models)", _SCIPY),
    SubModel("normal_model", "jkr_force", "JKR broken where the force reaches -F_c, as LAMMPS's jkr "
             "(model.adhesion_models)", _SCIPY),
    SubModel("tangential_model", "rigid", "the paper's rigid contact: the closed-form map (model.tangential)", _ALL),
    _dem("tangential_model", "mindlin", "Mindlin's elastic contact with micro-slip (model.tangential_compliance)",
         coupled=True, **_G),
    _dem("tangential_model", "mindlin_deresiewicz", "Mindlin-Deresiewicz: with load history "
         "(model.tangential_compliance)", coupled=True, **_G),
    _dem("tangential_model", "linear_history", "LAMMPS's linear_history k_t (model.dem_tangential)",
         tangential_stiffness=100.0),  # [N/m]
    *(_dem("tangential_model", name, f"LAMMPS's {name.removeprefix('lammps_')} (model.dem_tangential)", **_G)
      for name in DEM_TANGENTIAL_MODELS if name != "linear_history"),
    SubModel("friction_model", "net", "the paper's Coulomb limit f |F_n|", _ALL),
    _dem("friction_model", "pulloff", "the adhesion-aware limit f (F_n + 2 F_po)", coupled=True),
    SubModel("damping_model", "paper", "the paper's damping zeta_H, zeta_A, Eq. (27) (model.law)", _ALL, coupled=True),
    *(SubModel("damping_model", name, f"LAMMPS's {name} damping (model.dem_damping)", _SCIPY, coef)
      for name, coef in (("mass_velocity", {"damping_coefficient": 1e5}),  # eta_n0 [1/s]
                         ("viscoelastic", {"damping_coefficient": 1e5}),  # eta_n0 [1/(m s)]
                         ("tsuji", {"damping_coefficient": 0.6}),  # the restitution e [-]
                         ("coeff_restitution", {"damping_coefficient": 0.6}))),
    SubModel("rolling_model", "torque", "the constant rolling torque mu_r r |F_n| (none while mu_r is 0)", _ALL),
    _dem("rolling_model", "lammps_sds", "LAMMPS's rolling sds (model.dem_rolling)",
         rolling_stiffness=50.0, rolling_friction=0.1),  # [N/m], [-]
    SubModel("twisting_model", "none", "no twisting law (the paper's twist torque, or none with LAMMPS's laws)", _ALL),
    _dem("twisting_model", "lammps_sds", "LAMMPS's twisting sds (model.dem_twisting)",
         twisting_stiffness=1e-12, twisting_friction=3e-8),  # [N m/rad], [m]
    _dem("twisting_model", "lammps_marshall", "LAMMPS's twisting marshall (model.dem_twisting)"),
)
_REGISTRY: dict[str, dict[str, SubModel]] = {}
for _s in _DECLARED:
    _REGISTRY.setdefault(_s.field, {})[_s.name] = _s
# the Contact record and the registry name the same choices (a law added in one place only fails here)
if {f: tuple(v) for f, v in _REGISTRY.items()} != dict(_contact.SUB_MODELS):
    raise ImportError("microimpact.model.laws: the registry and Contact.SUB_MODELS name different sub-models")
if set(DEM_ROLLING_MODELS) | set(DEM_TWISTING_MODELS) > set(itertools.chain(*(_REGISTRY[f] for f in _REGISTRY))):
    raise ImportError("microimpact.model.laws: a LAMMPS rolling or twisting law is not declared")


def fields() -> tuple[str, ...]:
    """The Contact fields that select a law, in the registry's order.

    Examples
    --------
    >>> fields()[:2]
    ('normal_model', 'tangential_model')
    """
    return tuple(_REGISTRY)


def names(field_: str = "normal_model") -> tuple[str, ...]:
    """The choices of ``field_``, its default first.

    Examples
    --------
    >>> names()
    ('ring', 'jkr', 'dmt', 'jkr_force')
    """
    if field_ not in _REGISTRY:
        raise ValueError(f"field must be one of {', '.join(_REGISTRY)}, got {field_!r}")
    return tuple(_REGISTRY[field_])


def get(name: str, field_: str = "normal_model") -> SubModel:
    """The declared law ``name`` of ``field_``: the one lookup by name; ValueError naming both else.

    Examples
    --------
    >>> get("jkr_force").methods
    ('engine', 'reference')
    >>> get("mindlin", "tangential_model").parameters["shear_modulus"]
    300000000.0
    """
    choices = _REGISTRY.get(field_)
    if choices is None:
        raise ValueError(f"field must be one of {', '.join(_REGISTRY)}, got {field_!r}")
    if name not in choices:
        raise ValueError(f"{field_} must be one of {', '.join(choices)}, got {name!r}")
    return choices[name]


def coupled_refusal(choices: Mapping[str, str]) -> str | None:
    """The law of ``choices`` (field -> name) that the coupled solver does not integrate while another
    choice needs that solver (:attr:`SubModel.coupled`), as its field; None where there is none.

    Examples
    --------
    >>> coupled_refusal({"normal_model": "jkr", "tangential_model": "mindlin", "friction_model": "net",
    ...                  "damping_model": "paper"})
    'normal_model'
    """
    if choices["tangential_model"] in DEM_TANGENTIAL_MODELS:  # their own solver (solvers.dem_tangential)
        return None
    if not any(get(choices[f], f).coupled for f in ("tangential_model", "friction_model")):
        return None
    return next((f for f in ("damping_model", "normal_model") if not get(choices[f], f).coupled), None)


def supported(method: str) -> dict[str, tuple[str, ...]]:
    """What solver path ``method`` covers: field -> the names whose declaration lists it.

    Examples
    --------
    >>> supported("rkg")["normal_model"]
    ('ring',)
    """
    return {f: tuple(n for n, s in choices.items() if method in s.methods) for f, choices in _REGISTRY.items()}


@dataclass(frozen=True)
class Combination:
    """One law x sub-model combination a Contact accepts.

    Attributes
    ----------
    choices : Mapping of str to str
        field -> name, for every field of :func:`fields`.
    contact : Contact
        The combination on the base contact, with each sub-model's default parameters.
    methods : tuple of str
        The solver paths that cover every one of its choices.
    """

    choices: Mapping[str, str]
    contact: _contact.Contact
    methods: tuple[str, ...]


def combinations(base: _contact.Contact | None = None) -> Iterator[Combination]:
    """Every combination of the declared laws that a Contact accepts, on ``base`` and on its Hertz
    (f0 = 0) twin, with the parameters each sub-model documents (:attr:`SubModel.parameters`).

    ``base`` (default: Table 1 row 2 without its damping and with friction 0.3) gives the sphere
    and the adhesion; the paper's damping runs with the base's zeta_H, zeta_A, the others with 0.
    Combinations that the Contact refuses (a ValueError naming the rule) are left out.

    Examples
    --------
    >>> c = next(combinations())
    >>> dict(c.choices)["normal_model"], c.methods
    ('ring', ('engine', 'reference', 'rkg'))
    """
    if base is None:
        base = _contact.Contact(radius=3.45e-6, density=1350.0, stiffness=1.776e9, adhesion_line_force=7.422,
                                zeta_hertz=0.5, zeta_adhesion=29.0, friction=0.3)  # Table 1 row 2, f 0.3
    reset = {f.name: f.default for f in dataclasses.fields(_contact.Contact)
             if f.name not in ("radius", "density", "stiffness", "adhesion_line_force", "friction")}
    plain = replace(base, **reset)
    for f0 in dict.fromkeys((base.adhesion_line_force, 0.0)):
        for chosen in itertools.product(*(_REGISTRY[f].values() for f in _REGISTRY)):
            kwargs = {"adhesion_line_force": f0}
            for s in chosen:
                kwargs[s.field] = s.name
                kwargs.update(s.parameters)
            if kwargs["damping_model"] == "paper":
                kwargs.update(zeta_hertz=base.zeta_hertz, zeta_adhesion=base.zeta_adhesion)
            try:
                contact = replace(plain, **kwargs)
            except ValueError:
                continue
            choices = MappingProxyType({s.field: s.name for s in chosen})
            if coupled_refusal(choices) is not None:
                continue  # the solvers refuse it on every path (microimpact.solvers.check_sub_models)
            methods = tuple(m for m in _METHODS if all(m in s.methods for s in chosen))
            yield Combination(choices, contact, methods)


# --------------------------------------------------------------------------- laws fitted to e_n(v_n)
@dataclass(frozen=True)
class RestitutionLaw:
    """A law that ``microimpact fit --law NAME`` fits to measured e_n(v_n) and the model comparison ranks.

    Attributes
    ----------
    name : str
        Its name on the command line (``--law``) and in the comparison (``normal_model``).
    summary : str
        One line: what it is and where it is written.
    parameters : tuple of str
        The parameters the fit varies.
    fit : str
        The function that fits it (module.function).
    rate_independent : bool
        True for a law without the paper's damping (fitted by its own module, not with zeta_H, zeta_A).
    """

    name: str
    summary: str
    parameters: tuple[str, ...]
    fit: str
    rate_independent: bool = False


_RESTITUTION_LAWS = {law.name: law for law in (
    RestitutionLaw("damping", "the paper's ring force with its damping, Eqs. (4)-(7), (14)-(15), (27) (model.law)",
                   ("zeta_hertz", "zeta_adhesion", "work_of_adhesion"), "microimpact.analysis.fitting.fit_damping"),
    RestitutionLaw("thornton_ning", "Thornton & Ning (1998) elastic-plastic adhesive law, (TN1)-(TN12) "
                   "(model.thornton_ning)", ("yield_velocity", "work_of_adhesion"),
                   "microimpact.analysis.plastic_fit.fit_thornton_ning", rate_independent=True),
)}


def restitution_laws() -> tuple[str, ...]:
    """The names of the laws fitted to e_n(v_n), the paper's damping law first.

    Examples
    --------
    >>> restitution_laws()
    ('damping', 'thornton_ning')
    """
    return tuple(_RESTITUTION_LAWS)


def restitution_law(name: str) -> RestitutionLaw:
    """The declared law ``name`` of :func:`restitution_laws`; ValueError naming the choices else.

    Examples
    --------
    >>> restitution_law("thornton_ning").parameters
    ('yield_velocity', 'work_of_adhesion')
    """
    if name not in _RESTITUTION_LAWS:
        raise ValueError(f"law must be one of {', '.join(_RESTITUTION_LAWS)}, got {name!r}")
    return _RESTITUTION_LAWS[name]

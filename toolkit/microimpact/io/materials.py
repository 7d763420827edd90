"""Materials config: contact properties of named sphere/surface material pairs.

The bundled config is ``toolkit/microimpact/io/materials.yaml``, the only copy; its path is
:func:`default_materials_path`. The format is documented in ``data/README.md``, section
"Materials config", and enforced by :data:`MATERIALS_SCHEMA` (JSON Schema, unknown keys refused).

A pair stores material properties, not per-particle ones: the adhesion line force f0 follows from
the work of adhesion w_A for each particle radius through Eq. (7) of Cheng, Brach & Dunn (2002),
f0 = (9/(2 pi) K r w_A^2)^(1/3), so :meth:`MaterialPair.contact` takes the radius.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

import jsonschema
import yaml

from microimpact.model.contact import Contact, adhesion_line_force_from_work, stiffness_from_elastic
from microimpact.model.tangential_compliance import effective_shear_modulus, shear_modulus_from_elastic

__all__ = ["MaterialPair", "MaterialsError", "read_materials", "default_materials_path", "material_contact",
           "MATERIALS_SCHEMA"]

_ELASTIC = ("youngs_modulus_sphere", "poisson_sphere", "youngs_modulus_surface", "poisson_surface")


def _num(description: str, **bounds) -> dict:
    return {"type": "number", "description": description, **bounds}


_PAIR_SCHEMA = {
    "type": "object",
    "additionalProperties": False,
    "required": ["density", "work_of_adhesion"],
    "properties": {
        "description": {"type": "string", "description": "What the pair is."},
        "reference": {"type": "string", "description": "Where the values come from."},
        "density": _num("Sphere density. [kg/m^3]", exclusiveMinimum=0),
        "stiffness": _num("Effective stiffness K = 4 / (3 pi (k1 + k2)), Eq. (3). [Pa]", exclusiveMinimum=0),
        "youngs_modulus_sphere": _num("Young's modulus of the sphere E1. [Pa]", exclusiveMinimum=0),
        "poisson_sphere": _num("Poisson ratio of the sphere nu1. [-]", exclusiveMinimum=-1, exclusiveMaximum=0.5),
        "youngs_modulus_surface": _num("Young's modulus of the surface E2. [Pa]", exclusiveMinimum=0),
        "poisson_surface": _num("Poisson ratio of the surface nu2. [-]", exclusiveMinimum=-1, exclusiveMaximum=0.5),
        "work_of_adhesion": _num("Dupre work of adhesion w_A; f0 follows from Eq. (7). [J/m^2]", minimum=0),
        "friction": _num("Coulomb friction coefficient f. [-]", minimum=0),
        "zeta_hertz": _num("zeta_H, Eq. (15), of the pair used without a fit (the fit ignores it). [-]", minimum=0),
        "zeta_adhesion": _num("zeta_A, Eq. (14), of the pair used without a fit (the fit ignores it). [-]", minimum=0),
        "damping_reference_speed": _num("Fixed reference speed v_n of Eqs. (14)-(15). [m/s]", exclusiveMinimum=0),
        "shear_modulus_sphere": _num("Shear modulus of the sphere G1 (default E1 / (2 (1 + nu1))). [Pa]",
                                     exclusiveMinimum=0),
        "shear_modulus_surface": _num("Shear modulus of the surface G2 (default E2 / (2 (1 + nu2))). [Pa]",
                                      exclusiveMinimum=0),
    },
    # the shear moduli need the Poisson ratios (G* = 1 / ((2 - nu1)/G1 + (2 - nu2)/G2))
    "dependentRequired": {"shear_modulus_sphere": list(_ELASTIC), "shear_modulus_surface": list(_ELASTIC)},
    # either stiffness alone, or all four elastic constants without stiffness
    "oneOf": [
        {"required": ["stiffness"], "not": {"anyOf": [{"required": [k]} for k in _ELASTIC]}},
        {"required": list(_ELASTIC), "not": {"required": ["stiffness"]}},
    ],
}

#: JSON Schema of a materials config file
MATERIALS_SCHEMA: dict = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "microimpact materials config",
    "type": "object",
    "additionalProperties": False,
    "required": ["pairs"],
    "properties": {
        "pairs": {
            "type": "object",
            "minProperties": 1,
            "propertyNames": {"pattern": r"^[A-Za-z][A-Za-z0-9_]*$"},
            "additionalProperties": _PAIR_SCHEMA,
        }
    },
}


class MaterialsError(ValueError):
    """A materials config that cannot be used; the message lists every problem with its key path.

    Examples
    --------
    Every problem of the file is listed, each with its key path:

    >>> from pathlib import Path
    >>> _ = Path("m.yaml").write_text("pairs:\\n  a: {density: -1}\\n")
    >>> try:
    ...     read_materials("m.yaml")
    ... except MaterialsError as err:
    ...     print(err.source, len(err.problems)); print(err.problems[-1])
    m.yaml 3
    m.yaml: pairs.a.density: -1 is not > 0
    """

    def __init__(self, source: str, problems: list[str]):
        self.source = str(source)
        self.problems = tuple(problems)
        super().__init__("\n".join(self.problems))


@dataclass(frozen=True)
class MaterialPair:
    """Contact properties of a sphere material on a surface material.

    Parameters
    ----------
    name : str
        Key of the pair in the config, as used in the ``material_pair`` column of impact files.
    density : float
        Sphere density. [kg/m^3]
    stiffness : float
        Effective stiffness K, Eq. (3); computed from the elastic constants when those are given. [Pa]
    work_of_adhesion : float
        Dupre work of adhesion w_A. [J/m^2]
    friction : float
        Coulomb friction coefficient f. [-]
    zeta_hertz, zeta_adhesion : float
        Damping coefficients zeta_H, zeta_A, Eqs. (14)-(15), of :meth:`contact`: the pair used
        without a fit. :func:`~microimpact.analysis.fitting.fit_damping` ignores them (it starts
        from a grid) and its :class:`~microimpact.analysis.fitting.DampingFit` replaces them. [-]
    damping_reference_speed : float or None
        Fixed reference speed of Eqs. (14)-(15); None uses each impact's normal speed. [m/s]
    youngs_modulus_sphere, poisson_sphere, youngs_modulus_surface, poisson_surface : float or None
        Elastic constants E1 [Pa], nu1 [-], E2 [Pa], nu2 [-], when the pair was given that way.
    shear_modulus_sphere, shear_modulus_surface : float or None
        Shear moduli G1, G2 when given; else, with the elastic constants, the isotropic
        E / (2 (1 + nu)) (:attr:`effective_shear_modulus`). [Pa]
    description, reference : str
        Free text.

    Examples
    --------
    A pair of the bundled config and the contact it gives at a radius:

    >>> pair = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> pair.density, pair.work_of_adhesion, pair.friction
    (1350.0, 0.215834, 0.15)
    >>> c = pair.contact(3.45e-6)
    >>> ratio = c.work_of_adhesion / pair.work_of_adhesion
    >>> c.radius, c.stiffness == pair.stiffness, round(ratio, 12)
    (3.45e-06, True, 1.0)
    """

    name: str
    density: float
    stiffness: float
    work_of_adhesion: float
    friction: float = 0.0
    zeta_hertz: float = 0.0
    zeta_adhesion: float = 0.0
    damping_reference_speed: float | None = None
    youngs_modulus_sphere: float | None = None
    poisson_sphere: float | None = None
    youngs_modulus_surface: float | None = None
    poisson_surface: float | None = None
    shear_modulus_sphere: float | None = None
    shear_modulus_surface: float | None = None
    description: str = ""
    reference: str = ""

    @property
    def effective_shear_modulus(self) -> float | None:
        """G* = 1 / ((2 - nu1)/G1 + (2 - nu2)/G2) of the Mindlin tangential stiffness 8 G* a. [Pa]

        G1, G2 are the configured shear moduli, or the isotropic E / (2 (1 + nu)) of each material
        (:mod:`microimpact.model.tangential_compliance`); None for a pair given by its stiffness K
        alone (no Poisson ratios).
        """
        if self.poisson_sphere is None or self.poisson_surface is None:
            return None
        g1 = self.shear_modulus_sphere or float(shear_modulus_from_elastic(self.youngs_modulus_sphere, self.poisson_sphere))
        g2 = self.shear_modulus_surface or float(shear_modulus_from_elastic(self.youngs_modulus_surface, self.poisson_surface))
        return float(effective_shear_modulus(g1, self.poisson_sphere, g2, self.poisson_surface))

    def adhesion_line_force(self, radius: float) -> float:
        """f0 for a sphere of this radius, Eq. (7). [N/m]

        Parameters
        ----------
        radius : float
            Sphere radius. [m]
        """
        return adhesion_line_force_from_work(self.stiffness, radius, self.work_of_adhesion)

    def contact(self, radius: float) -> Contact:
        """The :class:`~microimpact.Contact` of a sphere of this radius, f0 from Eq. (7).

        Parameters
        ----------
        radius : float
            Sphere radius. [m]

        Returns
        -------
        Contact
            From :func:`material_contact` (the stiffness already follows from the elastic
            constants when those were given).
        """
        return material_contact(self, radius)


#: fields of a material record that a :class:`~microimpact.Contact` takes (besides the radius)
_MATERIAL_FIELDS = ("density", "stiffness", "work_of_adhesion", "friction", "zeta_hertz", "zeta_adhesion",
                    "damping_reference_speed", "shear_modulus")


def material_contact(material, radius: float, **changes) -> Contact:
    """The Contact of a sphere of ``radius`` made of ``material``: f0 from w_A by Eq. (7).

    The one builder of "the contact of radius r from the work of adhesion" for every material
    record of the toolkit: :class:`MaterialPair`, :class:`~microimpact.analysis.fitting.DampingFit`,
    :class:`~microimpact.analysis.fitting.FitProblem` or a :class:`~microimpact.Contact` (which is
    returned unchanged at its own radius, else moved with :meth:`~microimpact.Contact.at_radius`).

    Parameters
    ----------
    material : object
        Has ``density`` [kg/m^3], ``stiffness`` [Pa] and ``work_of_adhesion`` [J/m^2]; optionally
        ``friction``, ``zeta_hertz``, ``zeta_adhesion`` [-] (default 0) and
        ``damping_reference_speed`` [m/s] (default None: each impact's own normal speed).
    radius : float
        Sphere radius. [m]
    **changes
        Values that replace the material's (e.g. trial zetas and w_A of a fit).

    Returns
    -------
    Contact

    Raises
    ------
    ValueError
        If ``material`` lacks density, stiffness or work of adhesion, or a value is invalid.

    Examples
    --------
    The bundled pair of the synthetic data at the radius 1.29 um: f0 from its w_A by Eq. (7):

    >>> from microimpact.io import read_materials
    >>> pair = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> c = material_contact(pair, 1.29e-6)
    >>> round(c.adhesion_line_force, 4), c.zeta_hertz
    (5.347, 0.5)
    """
    if isinstance(material, Contact) and not changes:
        return material if radius == material.radius else material.at_radius(radius)
    p = {k: getattr(material, k, None) for k in _MATERIAL_FIELDS} | changes
    if p["shear_modulus"] is None:  # a MaterialPair holds G1, G2 and the Poisson ratios: G*
        p["shear_modulus"] = getattr(material, "effective_shear_modulus", None)
    missing = [k for k in ("density", "stiffness", "work_of_adhesion") if p[k] is None]
    if missing:
        raise ValueError(f"a material needs {', '.join(missing)} to build a contact (a MaterialPair, DampingFit "
                         f"or Contact), got {type(material).__name__}")
    return Contact.from_work_of_adhesion(
        radius, p["density"], p["stiffness"], p["work_of_adhesion"], zeta_hertz=p["zeta_hertz"] or 0.0,
        zeta_adhesion=p["zeta_adhesion"] or 0.0, friction=p["friction"] or 0.0,
        damping_reference_speed=p["damping_reference_speed"], shear_modulus=p["shear_modulus"],
        **{k: v for k, v in changes.items() if k not in _MATERIAL_FIELDS})


def default_materials_path() -> Path:
    """Path of the materials config bundled with the package (``microimpact/io/materials.yaml``).

    Examples
    --------
    >>> default_materials_path().name
    'materials.yaml'
    """
    return Path(str(files("microimpact.io") / "materials.yaml"))


# --------------------------------------------------------------------------- YAML loading
class _Loader(yaml.SafeLoader):
    """SafeLoader that reads YAML 1.2 floats (``1.776e9``) and refuses duplicate keys."""


_Loader.add_implicit_resolver(  # YAML 1.1 needs '1.776e+9'; accept '1.776e9' and '380e9' too
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*\.[0-9_]*|\.[0-9_]+|[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)?$"
               r"|^[-+]?\.(?:inf|Inf|INF)$|^\.(?:nan|NaN|NAN)$"),
    list("-+0123456789."),
)


def _construct_mapping(loader, node, deep=False):
    seen: dict = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r} (first on line {seen[key] + 1})", key_node.start_mark)
        seen[key] = key_node.start_mark.line
    return loader.construct_mapping(node, deep)


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def _format_error(name: str, err: jsonschema.ValidationError) -> list[str]:
    path = ".".join(str(p) for p in err.absolute_path)
    where = f"{name}: {path}" if path else name
    v, inst = err.validator, err.instance
    if v == "exclusiveMinimum":
        return [f"{where}: {inst!r} is not > {err.validator_value}"]
    if v == "minimum":
        return [f"{where}: {inst!r} is not >= {err.validator_value}"]
    if v == "exclusiveMaximum":
        return [f"{where}: {inst!r} is not < {err.validator_value}"]
    if v == "type":
        return [f"{where}: {inst!r} is not a {err.validator_value} (units are given in the docs, not in the value)"]
    if v == "additionalProperties":
        allowed = sorted(err.schema.get("properties", {}))
        extra = sorted(set(inst) - set(allowed))
        return [f"{where}: unknown key {k!r}; allowed keys: {', '.join(allowed)}" for k in extra]
    if v == "required":
        return [f"{where}: {err.message.replace('property', 'key')}"]
    if v == "oneOf":
        given = [k for k in ("stiffness", *_ELASTIC) if k in inst]
        return [f"{where}: give either 'stiffness' or all four of {', '.join(_ELASTIC)}, not both "
                f"(given: {', '.join(given) or 'none'})"]
    if v == "pattern" or err.validator == "propertyNames":
        return [f"{where}: pair name {inst!r} must start with a letter and contain only letters, digits and '_'"]
    return [f"{where}: {err.message}"]


def read_materials(path=None) -> dict[str, MaterialPair]:
    """Read and validate a materials config.

    Parameters
    ----------
    path : str or os.PathLike, optional
        YAML file with a top-level ``pairs`` mapping (see data/README.md, "Materials config");
        None: the bundled config, :func:`default_materials_path`.

    Returns
    -------
    dict of str to MaterialPair
        The pairs by name, in file order.

    Raises
    ------
    MaterialsError
        If the file is not valid YAML or does not match :data:`MATERIALS_SCHEMA`; the message lists
        every problem as ``<file>: <key path>: <what is wrong>``, e.g.
        ``materials.yaml: pairs.alumina.density: -3 is not > 0``.

    Examples
    --------
    >>> pairs = read_materials()
    >>> pairs["ammonium_fluorescein_on_silicon"].density
    1350.0
    """
    source = os.fspath(default_materials_path() if path is None else path)
    name = Path(source).name
    try:
        doc = yaml.load(Path(source).read_text(encoding="utf-8"), Loader=_Loader)
    except UnicodeDecodeError as e:
        raise MaterialsError(source, [f"{name}: byte offset {e.start}: not valid UTF-8"]) from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f"{name}: line {mark.line + 1}, column {mark.column + 1}" if mark else name
        raise MaterialsError(source, [f"{where}: not valid YAML: {getattr(e, 'problem', None) or e}"]) from None
    if doc is None:
        raise MaterialsError(source, [f"{name}: the file is empty; expected a top-level 'pairs:' mapping"])
    validator = jsonschema.Draft202012Validator(MATERIALS_SCHEMA)
    errors = sorted(validator.iter_errors(doc), key=lambda e: [str(p) for p in e.absolute_path])
    problems = [msg for err in errors for msg in _format_error(name, err)]
    if not errors:  # JSON Schema numbers include .inf; a material property must be finite
        problems = [f"{name}: pairs.{key}.{k}: {v!r} is not a finite number"
                    for key, entry in doc["pairs"].items() for k, v in entry.items()
                    if isinstance(v, float) and not math.isfinite(v)]
    if problems:
        raise MaterialsError(source, problems)
    pairs: dict[str, MaterialPair] = {}
    for key, entry in doc["pairs"].items():
        entry = {k: (float(v) if isinstance(v, (int, float)) else v) for k, v in entry.items()}
        stiffness = entry.pop("stiffness", None)
        if stiffness is None:
            stiffness = stiffness_from_elastic(
                entry["youngs_modulus_sphere"], entry["poisson_sphere"],
                entry["youngs_modulus_surface"], entry["poisson_surface"],
            )
        pairs[key] = MaterialPair(name=key, stiffness=stiffness, **entry)
    return pairs

"""Tests of the materials config: microimpact.io.read_materials and MaterialPair."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from microimpact import Contact, presets
from microimpact.io import MaterialPair, MaterialsError, default_materials_path, read_materials
from microimpact.model.contact import stiffness_from_elastic

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def pairs():
    return read_materials(default_materials_path())


def test_default_path_is_inside_the_package_and_the_only_copy():
    path = default_materials_path()
    assert path.is_file() and path.parent.name == "io" and path.parent.parent.name == "microimpact"
    # one copy only: the packaged file (data/materials.yaml was a byte-identical duplicate)
    assert not (REPO / "data" / "materials.yaml").exists()


def test_bundled_config_comment_says_what_the_zetas_are_for():
    text = default_materials_path().read_text(encoding="utf-8")
    assert "starting values" not in text and "ignores them" in text
    assert "model/parameters.py" in text  # the Table 1 row 2 numbers name their one home


def test_bundled_pairs(pairs):
    assert set(pairs) == {"ammonium_fluorescein_on_silicon", "alumina_on_soda_lime_glass"}
    assert all(isinstance(p, MaterialPair) for p in pairs.values())


def test_table1_pair_reproduces_f0_of_table1(pairs):
    """w_A = 0.215834 J/m2 was chosen so that Eq. (7) gives f0 = 7.422 N/m at r = 3.45 um."""
    p = pairs["ammonium_fluorescein_on_silicon"]
    c = p.contact(3.45e-6)
    assert isinstance(c, Contact)
    # 6 significant digits in w_A -> f0 to ~1e-6 relative; Table 1 prints 4 digits
    assert c.adhesion_line_force == pytest.approx(7.422, rel=5e-5)
    assert p.adhesion_line_force(3.45e-6) == c.adhesion_line_force
    assert c.work_of_adhesion == pytest.approx(p.work_of_adhesion, rel=1e-12)
    ref = presets.WALL_1990
    for field in ("radius", "density", "stiffness", "zeta_hertz", "zeta_adhesion", "friction"):
        assert getattr(c, field) == pytest.approx(getattr(ref, field), rel=1e-12), field
    # f0 follows the particle size as r^(1/3) at fixed w_A
    assert p.contact(2 * 3.45e-6).adhesion_line_force == pytest.approx(c.adhesion_line_force * 2 ** (1 / 3))


def test_alumina_pair_from_elastic_constants(pairs):
    p = pairs["alumina_on_soda_lime_glass"]
    assert p.stiffness == pytest.approx(stiffness_from_elastic(380e9, 0.23, 70e9, 0.25), rel=1e-15)
    c = p.contact(2.5e-3)
    assert c.stiffness == pytest.approx(p.stiffness, rel=1e-15)
    assert (c.density, c.friction, c.adhesion_line_force) == (4000.0, 0.092, 0.0)


def test_material_pair_is_frozen(pairs):
    with pytest.raises(dataclasses.FrozenInstanceError):
        pairs["alumina_on_soda_lime_glass"].density = 1.0


GOOD_PAIR = "    density: 1000\n    stiffness: 1e9\n    work_of_adhesion: 0.1\n"

BAD_CONFIGS = {
    "negative density": ("pairs:\n  alumina:\n    density: -3\n    stiffness: 1e9\n    work_of_adhesion: 0\n",
                         ["materials.yaml: pairs.alumina.density: -3 is not > 0"]),
    "unknown key": ("pairs:\n  a:\n" + GOOD_PAIR + "    frictoin: 0.1\n",
                    ["pairs.a: unknown key 'frictoin'", "allowed keys:", "friction"]),
    "unknown top key": ("pairs:\n  a:\n" + GOOD_PAIR + "extra: 1\n", ["materials.yaml: unknown key 'extra'"]),
    "missing key": ("pairs:\n  a:\n    stiffness: 1e9\n    work_of_adhesion: 0.1\n",
                    ["pairs.a: 'density' is a required key"]),
    "stiffness and elastic": ("pairs:\n  a:\n" + GOOD_PAIR + "    youngs_modulus_sphere: 1e9\n",
                              ["pairs.a: give either 'stiffness' or all four", "given: stiffness, youngs_modulus_sphere"]),
    "partial elastic": ("pairs:\n  a:\n    density: 1\n    work_of_adhesion: 0\n    youngs_modulus_sphere: 1e9\n",
                        ["pairs.a: give either 'stiffness' or all four"]),
    "poisson": ("pairs:\n  a:\n    density: 1\n    work_of_adhesion: 0\n    youngs_modulus_sphere: 1e9\n"
                "    poisson_sphere: 0.6\n    youngs_modulus_surface: 1e9\n    poisson_surface: 0.3\n",
                ["pairs.a.poisson_sphere: 0.6 is not < 0.5"]),
    "unit in value": ("pairs:\n  a:\n    density: 1000 kg/m3\n    stiffness: 1e9\n    work_of_adhesion: 0\n",
                      ["pairs.a.density: '1000 kg/m3' is not a number"]),
    "negative w_A": ("pairs:\n  a:\n    density: 1\n    stiffness: 1e9\n    work_of_adhesion: -0.1\n",
                     ["pairs.a.work_of_adhesion: -0.1 is not >= 0"]),
    "bad name": ("pairs:\n  Bad-name:\n" + GOOD_PAIR, ["pair name 'Bad-name'"]),
    "no pairs": ("pairs: {}\n", ["materials.yaml: pairs:"]),
    "duplicate pair": ("pairs:\n  a:\n" + GOOD_PAIR + "  a:\n" + GOOD_PAIR,
                       ["line 6", "duplicate key 'a' (first on line 2)"]),
    "yaml syntax": ("pairs:\n  a: [1, 2\n", ["materials.yaml: line 3", "not valid YAML"]),
    "empty": ("", ["materials.yaml: the file is empty"]),
}


@pytest.mark.parametrize("case", sorted(BAD_CONFIGS))
def test_bad_config_names_file_and_key_path(tmp_path, case):
    text, fragments = BAD_CONFIGS[case]
    path = tmp_path / "materials.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(MaterialsError) as info:
        read_materials(path)
    assert isinstance(info.value, ValueError)
    for fragment in fragments:
        assert fragment in str(info.value), f"{fragment!r} missing from:\n{info.value}"


def test_all_errors_listed_at_once(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text("pairs:\n  a:\n    density: -1\n    stiffness: 0\n    work_of_adhesion: 0\n    zeta_hertz: -2\n")
    with pytest.raises(MaterialsError) as info:
        read_materials(path)
    assert len(info.value.problems) == 3
    assert all(p.startswith("m.yaml: pairs.a.") for p in info.value.problems)


def test_yaml_1_2_floats_are_numbers(tmp_path):
    """PyYAML reads '1.776e9' and '380e9' as strings (YAML 1.1); the loader reads them as floats."""
    path = tmp_path / "m.yaml"
    path.write_text("pairs:\n  a:\n    density: 1350\n    youngs_modulus_sphere: 380e9\n    poisson_sphere: 0.23\n"
                    "    youngs_modulus_surface: 7.0E10\n    poisson_surface: -0.1\n    work_of_adhesion: 1.5e-2\n")
    p = read_materials(path)["a"]
    assert (p.youngs_modulus_sphere, p.youngs_modulus_surface, p.work_of_adhesion) == (380e9, 7e10, 0.015)
    assert isinstance(p.density, float) and p.friction == 0.0 and p.damping_reference_speed is None


def test_optional_fields_reach_the_contact(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text("pairs:\n  a:\n" + GOOD_PAIR + "    friction: 0.3\n    zeta_hertz: 0.2\n    zeta_adhesion: 4\n"
                    "    damping_reference_speed: 1.5\n    description: x\n    reference: y\n")
    c = read_materials(path)["a"].contact(1e-6)
    assert (c.friction, c.zeta_hertz, c.zeta_adhesion, c.damping_reference_speed) == (0.3, 0.2, 4.0, 1.5)
    assert c.adhesion_line_force == pytest.approx((9 / (2 * math.pi) * 1e9 * 1e-6 * 0.1**2) ** (1 / 3))


def test_material_contact_is_the_one_builder(pairs):
    from microimpact.io import material_contact

    p = pairs["ammonium_fluorescein_on_silicon"]
    c = material_contact(p, 2.0e-6)
    assert c == p.contact(2.0e-6)
    assert c.adhesion_line_force == p.adhesion_line_force(2.0e-6)
    assert material_contact(c, 2.0e-6) is c  # a Contact at its own radius is returned as it is
    moved = material_contact(c, 3.0e-6)
    assert moved == c.at_radius(3.0e-6)
    trial = material_contact(p, 2.0e-6, zeta_hertz=0.1, work_of_adhesion=0.1)
    assert (trial.zeta_hertz, trial.work_of_adhesion) == pytest.approx((0.1, 0.1), rel=1e-12)
    with pytest.raises(ValueError, match="needs density, stiffness, work_of_adhesion"):
        material_contact(object(), 1e-6)


def test_infinite_property_is_refused_naming_the_key(tmp_path):
    from microimpact.io import MaterialsError

    p = tmp_path / "m.yaml"
    p.write_text("pairs:\n  a_on_b: {density: .inf, stiffness: 1.0e+9, work_of_adhesion: 0.1}\n")
    with pytest.raises(MaterialsError, match=r"pairs\.a_on_b\.density: inf is not a finite number"):
        read_materials(p)

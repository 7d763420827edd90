"""Tests of microimpact.io.read_impacts: the measured-impact CSV format (data/README.md).

Every malformed file in tests/data/bad_csv/ must give ONE ImpactDataError whose message names the
file, the row and line (or the header), the column and the bad value, and must leave the file
byte-for-byte unchanged.
"""

from __future__ import annotations

import hashlib
import math
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from microimpact.io import (
    CANONICAL_COLUMNS,
    COLUMN_UNITS,
    ImpactDataError,
    ImpactDataWarning,
    default_materials_path,
    read_impacts,
    read_materials,
)
from microimpact.io.impacts import MAX_LISTED_PROBLEMS, label_variables, labels_from_dataset, row_labels
from microimpact.io.units import UNITS

DATA = Path(__file__).parent / "data"
BAD = DATA / "bad_csv"


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def write(tmp_path: Path, text: str, name: str = "impacts.csv") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


# --------------------------------------------------------------------------- malformed corpus
# file -> substrings the message must contain (besides the file name)
BAD_CASES = {
    "empty.csv": ["empty (0 bytes)", "expected a header line"],
    "header_only.csv": ["line 1", "no data rows"],
    "missing_size_and_rebound.csv": ["no particle size column", "'radius [unit]' or 'diameter [unit]'",
                                     "no rebound column", "'rebound_normal_speed [unit]'", "'e_n [1]'"],
    "speed_without_angle.csv": ["column 'speed [m/s]'", "needs 'incidence_angle [deg]'", "'normal_speed [m/s]'"],
    "duplicate_column.csv": ["line 1", "column 'radius [um]'", "the same column appears twice", "columns 1 and 2"],
    "duplicate_quantity_units.csv": ["column 'radius [m]'", "'radius' is given twice", "'radius [um]'"],
    "radius_and_diameter.csv": ["'radius [um]' and 'diameter [um]' both give the particle size"],
    "overdetermined_incident.csv": ["over-determine the incident velocity", "'normal_speed [m/s]'"],
    "no_unit.csv": ["column 'radius'", "has no unit", "'radius [unit]'", "um, µm"],
    "unit_in_parentheses.csv": ["column 'radius (um)'", "square brackets", "'radius [um]'"],
    "unknown_unit.csv": ["column 'radius [inch]'", "unit 'inch' is not accepted for a length",
                         "accepted units: m, mm, um"],
    "label_with_unit.csv": ["column 'size_class [um]'", "takes no unit"],
    "text_in_numeric.csv": ["row 2 (line 3)", "column 'speed [m/s]'", "value 'fast'", "not a number", "m/s"],
    "empty_required_cell.csv": ["row 2 (line 3)", "column 'e_n [1]'", "value ''", "required"],
    "nan_required_cell.csv": ["row 2 (line 3)", "column 'radius [um]'", "value 'NaN'", "required"],
    "inf_value.csv": ["row 2 (line 3)", "column 'speed [m/s]'", "value 'inf'", "not finite"],
    "nonpositive_speed.csv": ["row 2 (line 3)", "value '0'", "row 3 (line 4)", "value '-2.0'",
                              "column 'speed [m/s]'", "must be > 0"],
    "nonpositive_radius.csv": ["row 1 (line 2)", "column 'radius [um]'", "value '0'", "must be > 0"],
    "e_n_out_of_range.csv": ["row 2 (line 3)", "value '1.2'", "row 3 (line 4)", "value '-0.1'",
                             "column 'e_n [1]'", "in [0, 1]"],
    "angle_out_of_range.csv": ["row 2 (line 3)", "value '90'", "row 3 (line 4)", "value '-5'",
                               "column 'incidence_angle [deg]'", "in [0, 90) deg"],
    "angle_rad_out_of_range.csv": ["row 1 (line 2)", "column 'incidence_angle [rad]'", "value '1.7'",
                                   "97.4", "in [0, 90) deg"],
    "negative_uncertainty.csv": ["row 2 (line 3)", "column 'e_n_uncertainty [1]'", "value '-0.02'", ">= 0"],
    "uncertainty_without_quantity.csv": ["column 'rebound_angle_uncertainty [deg]'", "without a 'rebound_angle'"],
    "rebound_faster_than_incident.csv": ["row 2 (line 3)", "column 'rebound_normal_speed [m/s]'", "value '1.5'",
                                         "e_n = 1.5 > 1"],
    "ragged_row.csv": ["row 2 (line 3)", "6 fields but the header has 5", "decimal comma"],
    "duplicate_id.csv": ["row 2 (line 3)", "column 'id'", "value 'a1'", "not unique (first on row 1)"],
    "semicolon.csv": ["line 1", "';' (semicolon)", "',' (comma) is required"],
    "unknown_material_pair.csv": ["row 2 (line 3)", "column 'material_pair'", "value 'unobtainium_on_glass'",
                                  "known pairs: alumina_on_soda_lime_glass, ammonium_fluorescein_on_silicon"],
    "many_problems.csv": ["4 problems", "row 2 (line 4)", "column 'diameter [um]'", "value '-6.9'",
                          "row 3 (line 5)", "value 'abc'", "value '95'", "row 4 (line 6)", "value '2'"],
    "non_utf8.csv": ["line 3", "byte 0xE9 at byte offset 99", "not valid UTF-8"],
}
ACCEPTED = {"bom_accepted.csv"}


def test_every_corpus_file_has_a_case():
    on_disk = {p.name for p in BAD.glob("*.csv")}
    assert on_disk == set(BAD_CASES) | ACCEPTED


def test_corpus_bytes_are_what_they_claim():
    # guard against an editor "fixing" the committed bytes
    assert (BAD / "empty.csv").stat().st_size == 0
    assert (BAD / "bom_accepted.csv").read_bytes().startswith(b"\xef\xbb\xbf")
    with pytest.raises(UnicodeDecodeError):
        (BAD / "non_utf8.csv").read_bytes().decode("utf-8")


@pytest.mark.parametrize("name", sorted(BAD_CASES))
def test_bad_file_is_refused_with_located_message(name):
    path = BAD / name
    before = sha256(path)
    materials = default_materials_path() if "material" in name else None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactDataWarning)
        with pytest.raises(ImpactDataError) as info:
            read_impacts(path, materials=materials)
    message = str(info.value)
    assert isinstance(info.value, ValueError)
    assert f"impact file {path}" in message
    assert f"  - {name}" in message  # each problem line starts with the file name
    for fragment in BAD_CASES[name]:
        assert fragment in message, f"{fragment!r} missing from:\n{message}"
    assert info.value.problems and info.value.source == str(path)
    assert sha256(path) == before


def test_problems_are_structured():
    with pytest.raises(ImpactDataError) as info:
        read_impacts(BAD / "text_in_numeric.csv")
    (p,) = info.value.problems
    assert (p.row, p.line, p.column, p.value) == (2, 3, "speed [m/s]", "fast")


def test_bom_is_accepted_silently():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        df = read_impacts(BAD / "bom_accepted.csv")
    assert list(df["id"]) == ["a1"]
    assert df["radius"].iloc[0] == pytest.approx(3.45e-6, rel=1e-15)


def test_semicolon_is_refused_before_misreading_decimal_commas():
    with pytest.raises(ImpactDataError) as info:
        read_impacts(BAD / "semicolon.csv")
    assert len(info.value.problems) == 1


def test_long_problem_lists_are_capped_in_the_message_but_kept_in_full(tmp_path):
    n = MAX_LISTED_PROBLEMS + 50
    text = "radius [um],normal_speed [m/s],e_n [1]\n" + "3.45,1.0,7\n" * n
    with pytest.raises(ImpactDataError) as info:
        read_impacts(write(tmp_path, text))
    assert len(info.value.problems) == n
    assert "... and 50 more" in str(info.value)


# --------------------------------------------------------------------------- good files
def test_good_file_in_si_units():
    """tests/data/good_impacts.csv: diameter [um], speed [cm/s], angle [rad], rebound [mm/s]."""
    path = DATA / "good_impacts.csv"
    before = sha256(path)
    df = read_impacts(path, materials=default_materials_path())
    assert sha256(path) == before
    assert list(df.columns) == list(CANONICAL_COLUMNS)
    assert df.attrs["source"] == str(path) and df.attrs["sha256"] == before
    assert df.attrs["units"]["radius"] == "m" and df.attrs["units"]["incidence_deg"] == "deg"
    assert list(df["row"]) == [1, 2, 3] and list(df["line"]) == [2, 3, 4]
    assert list(df["id"]) == ["a1", "a2", "a3"]
    assert list(df["size_class"]) == ["small", "large", "large"]

    # hand-computed SI values
    rel = 1e-12  # only floating-point rounding separates these from the exact values
    exp = {
        "radius": [3.45e-6, 5e-6, 5e-6],
        "speed": [1.5, 2.0, 3.0],
        "incidence_deg": [0.0, 30.0, 30.0],
        "normal_speed": [1.5, 2.0 * math.sqrt(3) / 2, 3.0 * math.sqrt(3) / 2],
        "rebound_normal_speed": [0.9, 1.0, 1.2],
        "e_n": [0.6, 1.0 / math.sqrt(3), 1.2 / (1.5 * math.sqrt(3))],
        "speed_uncertainty": [0.05, 0.04, np.nan],
        "incidence_deg_uncertainty": [math.degrees(0.01), math.degrees(0.02), np.nan],
        "rebound_normal_speed_uncertainty": [0.02, 0.03, np.nan],
        "rebound_tangential_speed": [0.0, 0.5, np.nan],
        "rebound_angle_deg": [0.0, math.degrees(math.atan(0.5)), np.nan],
    }
    for col, values in exp.items():
        np.testing.assert_allclose(df[col], values, rtol=rel, atol=0, err_msg=col)
    # propagated: s_vn = hypot(cos a s_v, v sin a s_a); s_e = hypot(s_r / vn, r s_vn / vn^2)
    s_vn = [0.05, math.hypot(math.cos(math.pi / 6) * 0.04, 2.0 * 0.5 * 0.02), np.nan]
    np.testing.assert_allclose(df["normal_speed_uncertainty"], s_vn, rtol=rel)
    vn = exp["normal_speed"]
    s_e = [math.hypot(0.02 / vn[0], 0.9 * s_vn[0] / vn[0] ** 2),
           math.hypot(0.03 / vn[1], 1.0 * s_vn[1] / vn[1] ** 2), np.nan]
    np.testing.assert_allclose(df["e_n_uncertainty"], s_e, rtol=rel)
    # not given and not derivable
    assert df["radius_uncertainty"].isna().all()
    assert df["rebound_tangential_speed_uncertainty"].isna().all()


def test_normal_speed_only_and_alternative_forms(tmp_path):
    text = (
        "id,radius [m],normal_speed [mm/s],e_n [-],e_n_uncertainty [1],normal_speed_uncertainty [mm/s],"
        "rebound_angle [deg],rebound_angle_uncertainty [deg],notes\n"
        'x1,3.45e-6,1000,0.5,0.01,10,45,1,"free, text"\n'
        "x2,3.45e-6,2000,0.25,,,0,,\n"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImpactDataWarning)  # 'notes' is the analyst's own column: no warning
        df = read_impacts(write(tmp_path, text))
    assert df["notes"].tolist() == ["free, text", pd.NA]
    assert df["speed"].isna().all() and df["incidence_deg"].isna().all()
    np.testing.assert_allclose(df["normal_speed"], [1.0, 2.0], rtol=1e-15)
    np.testing.assert_allclose(df["rebound_normal_speed"], [0.5, 0.5], rtol=1e-15)
    # s_r = hypot(vn s_e, e s_vn)
    assert df["rebound_normal_speed_uncertainty"].iloc[0] == pytest.approx(math.hypot(1.0 * 0.01, 0.5 * 0.01))
    assert math.isnan(df["rebound_normal_speed_uncertainty"].iloc[1])
    # rebound_tangential_speed = r tan(b); s = hypot(tan b s_r, r s_b / cos^2 b)
    np.testing.assert_allclose(df["rebound_tangential_speed"], [0.5, 0.0], atol=1e-15)
    s_r = math.hypot(0.01, 0.005)
    assert df["rebound_tangential_speed_uncertainty"].iloc[0] == pytest.approx(
        math.hypot(1.0 * s_r, 0.5 * math.radians(1.0) / 0.5))


def test_normal_speed_with_angle_gives_speed(tmp_path):
    text = "diameter [nm],diameter_uncertainty [nm],normal_speed [m/s],incidence_angle [degree],rebound_normal_speed [m/s]\n" \
           "5000,100,1.0,60,0.5\n5000,,1.0,,0.5\n"
    df = read_impacts(write(tmp_path, text))
    assert df["radius"].iloc[0] == pytest.approx(2.5e-6, rel=1e-15)
    assert df["radius_uncertainty"].iloc[0] == pytest.approx(50e-9, rel=1e-15)
    assert df["speed"].iloc[0] == pytest.approx(2.0, rel=1e-12)
    assert math.isnan(df["speed"].iloc[1])
    np.testing.assert_allclose(df["e_n"], [0.5, 0.5])


def test_rebound_tangential_speed_gives_rebound_angle(tmp_path):
    text = ("radius [µm],speed [m/s],incidence_angle [°],rebound_normal_speed [m/s],rebound_tangential_speed [m/s],"
            "rebound_normal_speed_uncertainty [m/s],rebound_tangential_speed_uncertainty [m/s]\n"
            "3,2,0,1,1,0.1,0.1\n")
    df = read_impacts(write(tmp_path, text))
    assert df["rebound_angle_deg"].iloc[0] == pytest.approx(45.0)
    # s_b = hypot(r s_t, t s_r) / (r^2 + t^2) [rad]
    assert df["rebound_angle_deg_uncertainty"].iloc[0] == pytest.approx(math.degrees(math.hypot(0.1, 0.1) / 2))


def test_layout_quirks_are_tolerated(tmp_path):
    """CRLF, blank lines, all-empty spreadsheet rows, spaces, quoted labels, case of names."""
    text = ("\r\nRadius[um] , Speed [ m / s ],incidence_angle [deg],e_n [1],size_class\r\n"
            "3.45 , 1.0 ,10,0.5,\"small, round\"\r\n\r\n,,,,\r\n3.45,2.0,10,0.4,big\r\n")
    df = read_impacts(write(tmp_path, text))
    assert list(df["row"]) == [1, 2]
    assert list(df["line"]) == [3, 6]
    assert list(df["size_class"]) == ["small, round", "big"]
    np.testing.assert_allclose(df["speed"], [1.0, 2.0])


def test_empty_optional_cells_are_nan(tmp_path):
    text = "radius [um],normal_speed [m/s],e_n [1],e_n_uncertainty [1],id\n3.45,1,0.5,,\n"
    df = read_impacts(write(tmp_path, text))
    assert math.isnan(df["e_n_uncertainty"].iloc[0]) and pd.isna(df["id"].iloc[0])


def test_unknown_columns_warn_with_suggestion(tmp_path):
    text = "radius [um],normal_speed [m/s],e_n [1],raduis_uncertainty [um],operator\n3.45,1,0.5,0.1,kim\n"
    with pytest.warns(ImpactDataWarning, match=r"'raduis_uncertainty \[um\]' \(did you mean 'radius_uncertainty'\?\)") as rec:
        df = read_impacts(write(tmp_path, text))
    assert "operator" not in str(rec[0].message)  # a column of the analyst's own is no typo: no word about it
    # both are kept as text, as written (a typo'd quantity is not read as that quantity)
    assert df.attrs["kept_columns"] == ("raduis_uncertainty [um]", "operator")
    assert df["operator"].tolist() == ["kim"] and df["raduis_uncertainty [um]"].tolist() == ["0.1"]
    assert df["radius_uncertainty"].isna().all()


def test_the_analysts_own_columns_are_kept_as_text_and_named_as_written(tmp_path):
    text = ('id,operator,row,radius [um],normal_speed [m/s],e_n [1],operator,"note, free",\n'
            'a,kim,7,3.45,1,0.5,x,"n, 1",\n'
            'b,,8,3.45,2,0.4,y,,\n')
    df = read_impacts(write(tmp_path, text))
    # 'row' is a column of the table: the analyst's 'row' is csv_row; a repeated name gets _2; the
    # unnamed column of the trailing comma is dropped
    assert df.attrs["kept_columns"] == ("operator", "csv_row", "operator_2", "note, free")
    assert list(df.columns[-4:]) == ["operator", "csv_row", "operator_2", "note, free"]
    assert df["row"].tolist() == [1, 2] and df["csv_row"].tolist() == ["7", "8"]
    assert df["operator"].isna().tolist() == [False, True]
    labels = row_labels(df)
    assert labels.to_dict("list") == {"id": ["a", "b"], "operator": ["kim", ""], "csv_row": ["7", "8"],
                                      "operator_2": ["x", "y"], "note, free": ["n, 1", ""]}
    # rows of a selection keep their own labels, in their order
    assert row_labels(df.iloc[[1]]).to_dict("list")["id"] == ["b"]
    # NetCDF-safe variable names, the header name in an attribute, read back as it was
    ds = xr.Dataset(label_variables(labels, "impact"))
    assert sorted(ds.data_vars) == ["csv_note_free", "csv_operator", "csv_operator_2", "csv_row", "id"]
    assert labels_from_dataset(ds, "impact").to_dict("list") == labels.to_dict("list")


def test_materials_as_mapping_or_path():
    mats = read_materials(default_materials_path())
    a = read_impacts(DATA / "good_impacts.csv", materials=mats)
    b = read_impacts(DATA / "good_impacts.csv", materials=str(default_materials_path()))
    pd.testing.assert_frame_equal(a, b)
    with pytest.raises(ImpactDataError, match="unobtainium"):
        read_impacts(BAD / "unknown_material_pair.csv", materials={"ammonium_fluorescein_on_silicon": None})
    # without materials, labels are not checked
    assert len(read_impacts(BAD / "unknown_material_pair.csv")) == 2


def test_missing_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_impacts(tmp_path / "nope.csv")


@pytest.mark.extended
def test_large_file_loads(tmp_path):
    """200k rows load (vectorised checks); no timing assertion."""
    n = 200_000
    rng = np.random.default_rng(1)
    r, v, a = rng.uniform(1, 5, n), rng.uniform(0.5, 50, n), rng.uniform(0, 80, n)
    e = rng.uniform(0, 1, n)
    table = pd.DataFrame({"radius [um]": r, "speed [m/s]": v, "incidence_angle [deg]": a, "e_n [1]": e})
    path = tmp_path / "big.csv"
    table.to_csv(path, index=False)
    df = read_impacts(path)
    assert len(df) == n and df["row"].iloc[-1] == n and df["line"].iloc[-1] == n + 1
    np.testing.assert_allclose(df["normal_speed"], v * np.cos(np.radians(a)), rtol=1e-12)


# --------------------------------------------------------------------------- property test
_LENGTH_UNITS = list(UNITS["length"])
_SPEED_UNITS = list(UNITS["speed"])
_ANGLE_UNITS = list(UNITS["angle"])


@st.composite
def _tables(draw):
    n = draw(st.integers(1, 5))
    pos = st.floats(1e-3, 1e6, allow_nan=False, allow_infinity=False)
    return (
        draw(st.sampled_from(_LENGTH_UNITS)), draw(st.sampled_from(_SPEED_UNITS)),
        draw(st.sampled_from(_ANGLE_UNITS)),
        draw(st.lists(pos, min_size=n, max_size=n)), draw(st.lists(pos, min_size=n, max_size=n)),
        draw(st.lists(st.floats(0, 89.9), min_size=n, max_size=n)),
    )


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_tables())
def test_any_positive_values_in_any_unit_round_trip_to_si(table):
    lu, su, au, sizes, speeds, angles_deg = table
    factor_l, factor_s = UNITS["length"][lu], UNITS["speed"][su]
    angles = [a / UNITS["angle"][au] for a in angles_deg]  # in the file's angle unit
    lines = [f"radius [{lu}],speed [{su}],incidence_angle [{au}],e_n [1]"]
    lines += [f"{r!r},{v!r},{a!r},0.5" for r, v, a in zip(sizes, speeds, angles)]
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "p.csv"
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        df = read_impacts(path)
    np.testing.assert_allclose(df["radius"], np.array(sizes) * factor_l, rtol=1e-15)
    np.testing.assert_allclose(df["speed"], np.array(speeds) * factor_s, rtol=1e-15)
    np.testing.assert_allclose(df["incidence_deg"], angles_deg, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(df["normal_speed"], df["speed"] * np.cos(np.radians(df["incidence_deg"])))


def test_column_units_cover_numeric_columns():
    numeric = [c for c in CANONICAL_COLUMNS if c not in ("id", "size_class", "material_pair")]
    assert set(numeric) == set(COLUMN_UNITS)


def test_unit_table_refuses_with_the_accepted_list():
    from microimpact.io.units import UnitError, conversion_factor, parse_header_field, to_internal

    assert conversion_factor(" cm / s ", "speed") == 1e-2
    np.testing.assert_allclose(to_internal([1.0, 2.0], "rad", "angle"), np.degrees([1.0, 2.0]))
    with pytest.raises(UnitError, match="unit 'km/h' is not accepted for a speed; accepted units: m/s, cm/s, mm/s"):
        conversion_factor("km/h", "speed")
    assert parse_header_field(" Radius [ um ] ") == ("radius", "um")
    assert parse_header_field("id") == ("id", None)


# --------------------------------------------------------------------------- hostile bytes and layout (issue 12, part 6)
HEAD = "radius [um],normal_speed [m/s],e_n [1]\n"


def problems_of(path, **kw):
    with pytest.raises(ImpactDataError) as info:
        read_impacts(path, **kw)
    return info.value, str(info.value)


def test_nul_byte_is_refused_naming_row_and_column_not_stripped(tmp_path):
    p = tmp_path / "nul.csv"
    p.write_bytes((HEAD + "38.8\x00444,1,0.5\n2,1\x07,0.5\n3,1,0.5\n").encode())
    err, msg = problems_of(p)
    assert len(err.problems) == 2, msg  # one each, no second "not a number"
    assert "row 1 (line 2), column 'radius [um]'" in msg and "U+0000 (NUL)" in msg
    assert "row 2 (line 3), column 'normal_speed [m/s]'" in msg and "U+0007" in msg


@pytest.mark.filterwarnings("ignore::microimpact.io.ImpactDataWarning")
def test_control_character_in_header_and_label_is_refused(tmp_path):
    p = tmp_path / "ctl.csv"
    p.write_bytes(("id,radius\x1b [um],normal_speed [m/s],e_n [1]\na\x0c,1,1,0.5\n").encode())
    _, msg = problems_of(p)
    assert "line 1, column 'radius\\x1b [um]'" in msg and "U+001B (ESC)" in msg
    assert "row 1 (line 2), column 'id'" in msg and "U+000C (FF)" in msg


def test_tab_cr_lf_are_not_control_problems(tmp_path):
    p = tmp_path / "ws.csv"
    p.write_bytes((HEAD + "1\t,1,0.5\r\n2,1,0.5\r\n").encode())
    assert list(read_impacts(p)["radius"]) == [1e-6, 2e-6]


def test_leading_comments_and_excel_sep_line_are_skipped_and_lines_counted(tmp_path):
    p = write(tmp_path, "sep=,\n# lab: X, 2024\n\n  # operator: Y\n" + HEAD + "1,1,0.5\n2,x,0.5\n")
    _, msg = problems_of(p)
    assert "row 2 (line 7), column 'normal_speed [m/s]'" in msg and msg.count(" - ") == 1, msg
    p = write(tmp_path, '"sep=,"\n# lab notes\n' + HEAD + "1,1,0.5\n")
    df = read_impacts(p)
    assert list(df["line"]) == [4] and df["radius"][0] == 1e-6


def test_excel_sep_line_with_other_delimiter_is_refused_saying_what_it_is(tmp_path):
    p = write(tmp_path, "sep=;\nradius [um];normal_speed [m/s];e_n [1]\n1;1;0,5\n")
    err, msg = problems_of(p)
    assert len(err.problems) == 1 and "line 1" in msg and "Excel's delimiter line 'sep=;'" in msg


def test_only_comments_is_refused(tmp_path):
    _, msg = problems_of(write(tmp_path, "# nothing here\n# at all\n"))
    assert "only comment lines" in msg


def test_comment_after_header_is_not_skipped(tmp_path):
    # an id may start with '#': below the header nothing is dropped silently
    _, msg = problems_of(write(tmp_path, HEAD + "1,1,0.5\n# note\n"))
    assert "row 2 (line 3)" in msg


def test_unclosed_quote_names_its_row_and_does_not_dump_the_file(tmp_path):
    rows = "".join(f"{i},1,0.5\n" for i in range(1, 40))
    p = write(tmp_path, HEAD + "1,1,0.5\n\"2,1,0.5\n" + rows)
    err, msg = problems_of(p)
    assert len(err.problems) == 1, msg
    assert "row 2 (line 3), column 'radius [um]'" in msg and "never closed" in msg and "lines 3-42" in msg
    assert "39,1,0.5" not in msg  # the rest of the file is not dumped


def test_quote_closed_lines_later_names_row_and_keeps_checking_the_rest(tmp_path):
    p = write(tmp_path, HEAD + "\"1,1,0.5\n2\",1,0.5\n3,1,x\n")
    _, msg = problems_of(p)
    assert "row 1 (line 2), column 'radius [um]'" in msg and "on line 3" in msg
    assert "row 2 (line 4), column 'e_n [1]', value 'x'" in msg


def test_unclosed_quote_in_header(tmp_path):
    err, msg = problems_of(write(tmp_path, "\"" + HEAD + "1,1,0.5\n"))
    assert len(err.problems) == 1 and "line 1" in msg and "header" in msg


def test_overflow_of_a_derived_value_names_row_and_column(tmp_path):
    p = write(tmp_path, "radius [um],normal_speed [m/s],incidence_angle [deg],e_n [1]\n"
                        "1,1,10,0.5\n1,1e308,89.99999,0.5\n")
    err, msg = problems_of(p)
    assert len(err.problems) == 1, msg
    assert "row 2 (line 3), column 'normal_speed [m/s]', value '1e308'" in msg and "derived speed" in msg


def test_large_uncertainties_do_not_overflow_when_propagated(tmp_path):
    # squares of 1e300 overflow; the propagation must not (hypot)
    p = write(tmp_path, "radius [um],normal_speed [m/s],rebound_normal_speed [m/s],rebound_tangential_speed [m/s],"
                        "rebound_normal_speed_uncertainty [m/s],rebound_tangential_speed_uncertainty [m/s]\n"
                        "1,1.5e300,1e300,1e300,1e300,1e300\n")
    df = read_impacts(p)
    assert np.isfinite(df["rebound_angle_deg_uncertainty"][0])
    assert df["rebound_angle_deg"][0] == pytest.approx(45.0)


def test_radius_too_large_for_the_model_names_row_and_column(tmp_path):
    pair = "ammonium_fluorescein_on_silicon"
    p = write(tmp_path, HEAD.strip() + ",material_pair\n1,1,0.5," + pair + "\n1e308,1,0.5," + pair + "\n1e308,1,0.5,\n")
    err, msg = problems_of(p, materials=default_materials_path())
    assert len(err.problems) == 1, msg  # the row without a pair is not checked
    assert "row 2 (line 3), column 'radius [um]', value '1e308'" in msg and "adhesion_line_force" in msg
    err, msg = problems_of(p, materials=default_materials_path(), material_pair=pair)
    assert "row 3 (line 4)" in msg and len(err.problems) == 2
    with pytest.raises(ValueError, match="known pairs"):
        read_impacts(p, materials=default_materials_path(), material_pair="nope")


def test_a_workbook_or_netcdf_file_is_refused_in_one_line_saying_what_it_is(tmp_path):
    """An Excel workbook (a zip with an xl/ part) or a NetCDF file given as the CSV: one problem
    naming the kind and asking for a CSV export (issue 28: 316 and 4277 'invalid UTF-8' problems)."""
    import zipfile

    import xarray as xr

    from microimpact.io import ImpactDataError, read_impacts

    book = tmp_path / "impacts.xlsx"
    with zipfile.ZipFile(book, "w") as z:
        z.writestr("[Content_Types].xml", "<Types/>")
        z.writestr("xl/workbook.xml", "<workbook/>")
        z.writestr("xl/worksheets/sheet1.xml", "<worksheet/>")
    nc = tmp_path / "impacts.nc"
    xr.Dataset({"e_n": ("i", [0.5])}, attrs={"title": "some result"}).to_netcdf(nc)
    for path, kind in ((book, "an Excel workbook (.xlsx)"), (nc, "a NetCDF file titled 'some result'")):
        with pytest.raises(ImpactDataError) as info:
            read_impacts(path)
        assert len(info.value.problems) == 1, info.value
        assert f"the file is {kind}, not a CSV of measured impacts" in str(info.value)
        assert "save the measurements as CSV" in str(info.value)

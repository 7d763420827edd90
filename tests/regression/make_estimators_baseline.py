"""Fitted values on three data sets before the estimator rewrite (regression baseline)."""
import json, sys
from pathlib import Path
from microimpact.io import read_impacts, read_materials, default_materials_path
from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.oblique import fit_friction
from microimpact.analysis.synthetic import make_synthetic_oblique
from microimpact.io.files import write_csv
pairs = read_materials(default_materials_path())
pair = pairs["ammonium_fluorescein_on_silicon"]
out = {}
t = read_impacts(str(Path(__file__).resolve().parents[2] / "data" / "synthetic_microspheres.csv"), materials=pairs)
for wa in (False, True):
    f = fit_damping(t, pair, fit_work_of_adhesion=wa, confidence_intervals=False)
    out[f"bundled_fit_wA_{wa}"] = {"values": f.values, "stderr": f.stderr, "chisqr": f.chisqr}
import tempfile
tmp = Path(tempfile.mkdtemp()) / "obl_default.csv"
write_csv(make_synthetic_oblique(), tmp, float_format="%.6g")
t = read_impacts(tmp, materials=pairs)
f = fit_damping(t, pair, confidence_intervals=False)
ff = fit_friction(t, f)
out["synthetic_oblique_default"] = {"values": f.values, "stderr": f.stderr, "chisqr": f.chisqr,
                                    "friction": ff.values["friction"], "friction_stderr": ff.stderr["friction"],
                                    "friction_chisqr": ff.chisqr}
json.dump(out, sys.stdout, indent=1)

"""Lab-data input and atomic file output.

* :func:`read_impacts` - read and validate a CSV of measured impacts (format: data/README.md,
  "Measured-impact CSV format"); returns a DataFrame in canonical columns and SI units (angles in
  [deg] in ``*_deg`` columns), or raises one :class:`ImpactDataError` listing every problem.
* :func:`read_materials`, :func:`default_materials_path`, :class:`MaterialPair` - the materials
  config (data/README.md, "Materials config"); :func:`material_contact` - the Contact of a radius
  from any material record, f0 from w_A by Eq. (7).
* :func:`atomic_write`, :func:`atomic_path`, :func:`write_csv`, :func:`write_netcdf`,
  :func:`write_netcdf_groups` - writers that leave either the old or the complete new file, never a partial one.
* :mod:`microimpact.io.units` - the one table of accepted units.
"""

from microimpact.io import files, impacts, materials, units
from microimpact.io.files import atomic_path, atomic_write, write_csv, write_netcdf, write_netcdf_groups
from microimpact.io.impacts import CANONICAL_COLUMNS, COLUMN_UNITS, ImpactDataError, ImpactDataWarning, Problem, read_impacts
from microimpact.io.materials import MaterialPair, MaterialsError, default_materials_path, material_contact, read_materials
from microimpact.io.units import UNITS, UnitError

#: the public names of the readers and writers, each module's own list (one place each)
__all__ = [name for module in (impacts, materials, files) for name in module.__all__
           if name not in ("MAX_LISTED_PROBLEMS", "MATERIALS_SCHEMA", "NETCDF_COMPRESSION")] + ["UNITS", "UnitError"]

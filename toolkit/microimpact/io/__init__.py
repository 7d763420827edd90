"""Lab-data input and atomic file output.

* :func:`read_impacts` - read and validate a CSV of measured impacts (format: data/README.md,
  "Measured-impact CSV format"); returns a DataFrame in canonical columns and SI units (angles in
  [deg] in ``*_deg`` columns), or raises one :class:`ImpactDataError` listing every problem.
* :func:`read_materials`, :func:`default_materials_path`, :class:`MaterialPair` - the materials
  config (data/README.md, "Materials config"); :func:`material_contact` - the Contact of a radius
  from any material record, f0 from w_A by Eq. (7).
* :func:`atomic_write`, :func:`atomic_path`, :func:`write_csv`, :func:`write_netcdf`,
  :func:`write_netcdf_groups` - writers that leave either the old or the complete new file, never a partial one.
* :mod:`microimpact.io.units` - the one table of accepted units; :mod:`.variables` - the one table
  of result variable names, units and long names; :mod:`.provenance` - which parameters made a
  result.

The names above load their module on first use (PEP 562): importing a light part of io, such as
the variables table or the provenance attributes, does not import pandas or the CSV reader.
"""

from microimpact._lazy import lazy_exports as _lazy_exports

#: public name -> the module of microimpact.io that defines it
_HOMES = {
    **dict.fromkeys(("read_impacts", "material_pairs", "select_material_pair", "row_labels", "insert_row_labels", "label_variables", "labels_from_dataset", "ImpactDataError", "ImpactDataWarning", "Problem", "CANONICAL_COLUMNS",
                     "COLUMN_UNITS"), "impacts"),
    **dict.fromkeys(("MaterialPair", "MaterialsError", "read_materials", "default_materials_path",
                     "material_contact"), "materials"),
    **dict.fromkeys(("atomic_path", "atomic_write", "write_netcdf", "write_netcdf_groups", "write_csv",
                     "read_netcdf_groups"), "files"),
    **dict.fromkeys(("UNITS", "UnitError"), "units"),
}

__all__ = list(_HOMES)


#: the modules, importable as attributes
_MODULES = ("files", "formatting", "impacts", "kinds", "lammps", "materials", "paths",
            "provenance", "resources", "statuses", "units", "variables")


__getattr__, __dir__ = _lazy_exports("microimpact.io", _HOMES, _MODULES)

"""The Contact a command's options describe: a preset, a fit file or a materials config, and the fields given."""

from __future__ import annotations

import sys
from dataclasses import fields

from microimpact._commands.common import CONTACT_FIELDS, UsageError
from microimpact.io.paths import check_input_file
from microimpact.model.contact import Contact, adhesion_line_force_from_work
from microimpact.presets import PRESETS, get_preset


def _base_material(args):
    """(material, label): the preset Contact, a DampingFit or a MaterialPair, as the options say."""
    given = [o for o, v in (("--preset", args.preset), ("--fit", args.fit), ("--material-pair", args.material_pair))
             if v is not None]
    if len(given) > 1:
        raise UsageError(f"{' and '.join(given)} both name the material; give one of them")
    if args.config is not None and args.material_pair is None:
        raise UsageError("--config is read only with --material-pair")
    if args.fit is not None:
        from microimpact.analysis.fit_result import DampingFit  # only with --fit: the start-up of simulate

        path = check_input_file("--fit", args.fit)
        try:
            fit = DampingFit.load(path)
        except ValueError as exc:
            raise UsageError(f"--fit {args.fit}: {exc}") from None
        undetermined = [st.describe() for st in fit.identifiability.values() if not st.determined]
        if undetermined:
            print(f"microimpact: note: --fit {args.fit}: " + "; ".join(undetermined)
                  + "; its stored values are used", file=sys.stderr)
        return fit, f"fit {path.name} ({fit.parameter_source})"
    if args.material_pair is not None:
        from microimpact.io.materials import default_materials_path, read_materials  # only with --material-pair

        config = check_input_file("--config", args.config) if args.config else default_materials_path()
        pairs = read_materials(config)
        if args.material_pair not in pairs:
            raise UsageError(f"--material-pair {args.material_pair!r} is not in {config}; known: {', '.join(pairs)}")
        return pairs[args.material_pair], f"material pair {args.material_pair} of {config}"
    if args.preset is not None and not args.preset.strip():
        raise UsageError(f"--preset {args.preset!r}: an empty name names no preset; known: {', '.join(sorted(PRESETS))} "
                         "(or leave --preset out for wall1990)")
    name = args.preset if args.preset is not None else "wall1990"
    return get_preset(name), f"preset {name}"


def contact_from_args(args) -> Contact:
    """The contact the options describe; ``args.contact_note`` says where f0 came from.

    The material is kept at every size: with --radius (or --stiffness) but no --adhesion-line-force,
    f0 follows from the material's work of adhesion by Eq. (7) (Cheng, Brach & Dunn 2002), as a fit
    over several sizes assumes; --adhesion-line-force sets it explicitly. ValueError names a bad field.
    """
    material, label = _base_material(args)
    changes = {n: getattr(args, n) for n in CONTACT_FIELDS if getattr(args, n, None) is not None}
    replaced = ""
    if changes.get("damping_model", "paper") != "paper":
        # a DEM damping law replaces the paper's damping of the material, said in the note
        dropped = {n: None if n == "damping_reference_speed" else 0.0
                   for n in ("zeta_hertz", "zeta_adhesion", "damping_reference_speed") if n not in changes}
        changes = dropped | changes
        replaced = f"; damping_model {changes['damping_model']} replaces the paper's damping (zeta_H = zeta_A = 0)"
    radius = changes.get("radius")
    if isinstance(material, Contact):
        base = material
    else:  # a fit or a material pair: a contact exists only at a radius
        sizes = getattr(material, "radii", None)
        if radius is None and sizes is not None and len(sizes) == 1:
            radius = float(sizes[0])
        if radius is None:
            known = f" (the fit's sizes: {', '.join(f'{r:.4g}' for r in sizes)} m)" if sizes is not None else ""
            raise UsageError(f"give --radius with {'--fit' if args.fit else '--material-pair'}{known}")

        from microimpact.io.materials import material_contact  # only with --fit or --material-pair

        base = material_contact(material, radius)
    w_a = args.work_of_adhesion if args.work_of_adhesion is not None else base.work_of_adhesion
    if "adhesion_line_force" in changes:
        if args.work_of_adhesion is not None:
            raise UsageError("--adhesion-line-force and --work-of-adhesion both set f0; give one of them")
        contact = base.with_(**changes)
        note = f"f0 = {contact.adhesion_line_force:.6g} N/m given on the command line"
    elif changes.keys() & {"radius", "stiffness"} or args.work_of_adhesion is not None:
        c = base.with_(**changes)
        contact = c.with_(adhesion_line_force=adhesion_line_force_from_work(c.stiffness, c.radius, w_a))
        note = (f"f0 = {contact.adhesion_line_force:.6g} N/m from w_A = {w_a:.6g} J/m2 by Eq. (7) at "
                f"r = {contact.radius:.6g} m")
    else:
        contact = base.with_(**changes) if changes else base
        note = f"f0 = {contact.adhesion_line_force:.6g} N/m of the material"
    args.contact_note = f"{label}; {note}{replaced}"
    return contact


def contact_record(contact: Contact, note: str) -> dict:
    """Every Contact field (SI units, sub-models by name), the work of adhesion and where f0 came from."""
    out = {f.name: getattr(contact, f.name) for f in fields(Contact)}
    return out | {"work_of_adhesion": contact.work_of_adhesion, "source": note}

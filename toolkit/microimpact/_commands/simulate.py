"""``microimpact simulate``: one impact, printed as JSON."""

from __future__ import annotations

import json
import math
import sys

from microimpact._commands.common import UsageError
from microimpact._commands.contacts import contact_from_args, contact_record
from microimpact.model.adhesion_models import adhesion_scales
from microimpact.model.law import nondimensional_impact
from microimpact._runtime.signals import interpreted_budget_over
from microimpact.solvers.impact import simulate_impact


#: right-hand-side evaluations of the reference integration (DOP853) of an impact of the ring law:
#: a few hundred while the damping is light; overdamped (max(C1, C2) above a few) the sphere creeps
#: into its well over ~C nondimensional times at steps ~1/C (the explicit method's stability
#: limit), ~REFERENCE_EVALUATIONS_PER_C2 C^2 in all (measured at zeta_H = 1e3 and 3e3, 2 m/s:
#: 3579 and 25621 evaluations at C1 = 6.9 and 20.8)
REFERENCE_EVALUATIONS_PER_C2 = 75.0
#: the same for the reference integration of the adhesive JKR and DMT laws
#: (:func:`microimpact.solvers.normal_models.solve_normal_reference`, in the adhesion units, where C1,
#: C2 are the damping coefficients times the adhesion speed): 400 + K max(C1, C2)^2 with K per law,
#: measured with solve_ivp's counts at 0.2 and 2 m/s, zeta_H 1e3-1e4 (Table 1 row 2's sphere): JKR
#: 3248-590369 evaluations at C1 0.86-13.6 (2900-5800 C^2); DMT creeps less, 2348 and 9956 at C1 4.4
#: and 13.2 (0.2 m/s: 60-70 C^2; at 2 m/s it is stopped sooner, and the estimate is high). The JKR
#: right-hand side (a Newton solve for the contact radius) is slower, ~3-5 thousand a second, so the
#: same bounds below mean a few minutes (warning) and about an hour and more (refused)
REFERENCE_EVALUATIONS_PER_C2_ADHESIVE = {"jkr": 3500.0, "jkr_force": 3500.0, "dmt": 60.0}
#: evaluations refused before the work (~10-20 thousand a second: tens of minutes and more)
MAX_REFERENCE_EVALUATIONS = 2.0e7
#: evaluations above which a warning on stderr says the run will take a while (about a minute)
WARN_REFERENCE_EVALUATIONS = 1.0e6


def reference_evaluations(contact, normal_speed: float) -> float:
    """Right-hand-side evaluations the reference integration of one impact needs, roughly. [-]

    ``400 + REFERENCE_EVALUATIONS_PER_C2 max(C1, C2)^2`` with C1, C2 the nondimensional damping of
    :func:`microimpact.model.law.nondimensional_impact` (Eqs. (31)-(32)) for the paper's law.
    For the adhesive JKR and DMT laws the damping is made nondimensional in the adhesion units
    (:func:`microimpact.model.adhesion_models.adhesion_scales`) and the constant is the law's
    (``REFERENCE_EVALUATIONS_PER_C2_ADHESIVE``). Other laws (Hertz with a DEM damping law): 0,
    no estimate.
    """
    if contact.normal_model == "ring" and contact.damping_model == "paper":
        _, _, c1, c2 = nondimensional_impact(contact, normal_speed)
        return 400.0 + REFERENCE_EVALUATIONS_PER_C2 * max(c1, c2) ** 2
    if contact.normal_model in REFERENCE_EVALUATIONS_PER_C2_ADHESIVE and contact.adhesion_line_force > 0.0:
        speed = adhesion_scales(contact).speed
        c1, c2 = (c * speed for c in contact.damping_coefficients(normal_speed))
        return 400.0 + REFERENCE_EVALUATIONS_PER_C2_ADHESIVE[contact.normal_model] * max(c1, c2) ** 2
    if contact.damping_model == "paper" and contact.adhesion_line_force == 0.0:
        # JKR and DMT without adhesion: the Hertz law, run by the ring law's integration
        return reference_evaluations(contact.with_(normal_model="ring"), normal_speed)
    return 0.0


def _check_reference_work(args, contact) -> None:
    """UsageError before a reference run that would take hours; a warning before a long one."""
    if args.method != "reference":
        return
    work = reference_evaluations(contact, args.speed * math.cos(math.radians(args.incidence_deg)))
    if work > MAX_REFERENCE_EVALUATIONS:
        raise UsageError(f"--method reference: this damping needs about {work:.1e} evaluations of the equations "
                         f"(an overdamped sphere creeping into its well at the explicit method's smallest steps; "
                         f"at most {MAX_REFERENCE_EVALUATIONS:.0e} are run): use --method engine")
    if work > WARN_REFERENCE_EVALUATIONS:
        print(f"microimpact: --method reference: about {work:.1e} evaluations of the equations (overdamped); "
              "this takes a while (--method engine is faster)", file=sys.stderr, flush=True)


def run(args) -> int:
    contact = contact_from_args(args)
    _check_reference_work(args, contact)
    result = simulate_impact(contact, args.speed, args.incidence_deg, args.azimuth_deg,
                             (args.omega_n, args.omega_t, args.omega_tp), rtol=args.rtol, method=args.method)
    interpreted_budget_over()
    record = contact_record(contact, args.contact_note)
    if args.json:
        print(json.dumps(result.to_dict() | {"contact": record}, indent=2))
    else:
        d = result.to_dict() | {f"contact.{k}": v for k, v in record.items()}
        width = max(map(len, d))
        for k, v in d.items():
            print(f"{k:<{width}}  {v}")
    return 0

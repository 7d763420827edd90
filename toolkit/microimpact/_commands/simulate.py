"""``microimpact simulate``: one impact, printed as JSON."""

from __future__ import annotations

import json
import math
import sys

from microimpact._commands.common import UsageError
from microimpact._commands.contacts import contact_from_args, contact_record
from microimpact.model.law import nondimensional_impact
from microimpact._runtime.signals import interpreted_budget_over
from microimpact.solvers.impact import simulate_impact


#: right-hand-side evaluations of the reference integration (DOP853) of an impact of the ring law:
#: a few hundred while the damping is light; overdamped (max(C1, C2) above a few) the sphere creeps
#: into its well over ~C nondimensional times at steps ~1/C (the explicit method's stability
#: limit), ~REFERENCE_EVALUATIONS_PER_C2 C^2 in all (measured at zeta_H = 1e3 and 3e3, 2 m/s:
#: 3579 and 25621 evaluations at C1 = 6.9 and 20.8)
REFERENCE_EVALUATIONS_PER_C2 = 75.0
#: evaluations refused before the work (~10-20 thousand a second: tens of minutes and more)
MAX_REFERENCE_EVALUATIONS = 2.0e7
#: evaluations above which a warning on stderr says the run will take a while (about a minute)
WARN_REFERENCE_EVALUATIONS = 1.0e6


def reference_evaluations(contact, normal_speed: float) -> float:
    """Right-hand-side evaluations the reference integration of one impact needs, roughly. [-]

    ``400 + REFERENCE_EVALUATIONS_PER_C2 max(C1, C2)^2`` with C1, C2 the nondimensional damping of
    :func:`microimpact.model.law.nondimensional_impact` (Eqs. (31)-(32)).
    """
    _, _, c1, c2 = nondimensional_impact(contact, normal_speed)
    return 400.0 + REFERENCE_EVALUATIONS_PER_C2 * max(c1, c2) ** 2


def _check_reference_work(args, contact) -> None:
    """UsageError before a reference run that would take hours; a warning before a long one."""
    if args.method != "reference" or contact.normal_model != "ring":
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

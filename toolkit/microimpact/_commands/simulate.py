"""``microimpact simulate``: one impact, printed as JSON."""

from __future__ import annotations

import json

from microimpact._commands.contacts import contact_from_args, contact_record
from microimpact._runtime.signals import interpreted_budget_over
from microimpact.solvers.impact import simulate_impact


def run(args) -> int:
    contact = contact_from_args(args)
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

"""Command line: ``microimpact simulate | sweep | fit | flags | benchmark ...``.

Bad arguments print one line ``microimpact: error: ...`` to stderr and exit with status 2; nothing
is written then.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import fields

from . import __version__
from .params import Contact
from .presets import PRESETS, get_preset

__all__ = ["main", "build_parser"]


class UsageError(Exception):
    """A user error: reported in one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, status 2, as argparse does, but without the usage dump
        raise UsageError(message)


def _finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


CONTACT_FIELDS = [f.name for f in fields(Contact)]


def add_contact_options(p: argparse.ArgumentParser) -> None:
    """--preset plus one option per Contact field (SI units) that overrides the preset."""
    p.add_argument("--preset", default="wall1990", help=f"parameter preset ({', '.join(sorted(PRESETS))}); default wall1990")
    for name in CONTACT_FIELDS:
        p.add_argument(f"--{name.replace('_', '-')}", type=_finite_float, default=None, metavar="SI",
                       help=f"override Contact.{name} (SI units)")


def contact_from_args(args) -> Contact:
    """The preset with the overrides given on the command line; ValueError names a bad field."""
    base = get_preset(args.preset)
    changes = {n: getattr(args, n) for n in CONTACT_FIELDS if getattr(args, n, None) is not None}
    return base.with_(**changes) if changes else base


def _cmd_simulate(args) -> int:
    from .impact import simulate_impact

    contact = contact_from_args(args)
    result = simulate_impact(contact, args.speed, args.incidence_deg, args.azimuth_deg,
                             (args.omega_n, args.omega_t, args.omega_tp), rtol=args.rtol, method=args.method)
    if args.json:
        print(json.dumps(result.to_dict(), indent=2))
    else:
        d = result.to_dict()
        width = max(map(len, d))
        for k, v in d.items():
            print(f"{k:<{width}}  {v}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="microimpact", description="Microsphere contact/impact with smooth, flat surfaces.")
    parser.add_argument("--version", action="version", version=f"microimpact {__version__}")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)

    p = sub.add_parser("simulate", help="simulate one impact")
    add_contact_options(p)
    p.add_argument("--speed", type=_finite_float, required=True, help="incident speed [m/s]")
    p.add_argument("--incidence-deg", type=_finite_float, default=0.0, help="angle from the normal [deg]")
    p.add_argument("--azimuth-deg", type=_finite_float, default=0.0, help="azimuth in the tangent plane [deg]")
    p.add_argument("--omega-n", type=_finite_float, default=0.0, help="initial spin about n [rad/s]")
    p.add_argument("--omega-t", type=_finite_float, default=0.0, help="initial spin about t [rad/s]")
    p.add_argument("--omega-tp", type=_finite_float, default=0.0, help="initial spin about t' [rad/s]")
    p.add_argument("--rtol", type=_finite_float, default=1e-10, help="relative tolerance")
    p.add_argument("--method", choices=("engine", "reference"), default="engine")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=_cmd_simulate)

    for register in _EXTRA_COMMANDS:
        register(sub)
    return parser


# Other modules add subcommands here: callables taking the subparsers object.
_EXTRA_COMMANDS: list = []


def main(argv=None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if not getattr(args, "command", None):
            raise UsageError("a command is required: " + ", ".join(["simulate"] + [r.__name__.removeprefix("register_") for r in _EXTRA_COMMANDS]))
        return args.func(args)
    except (UsageError, ValueError) as exc:
        print(f"microimpact: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

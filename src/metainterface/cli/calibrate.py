"""`metainterface calibrate`: tau and w from a friction test of one sphere (JKR contact)."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "calibrate",
        help="fit the shear strength tau and work of adhesion w to a sphere friction test",
        description="Fit tau and w, with their uncertainty, to a friction test of one sphere "
        "on the material (Bowden-Tabor friction F_f = tau A on a JKR contact). The CSV is a "
        "friction law (normal_force,friction_force in N, or normal_force,friction_coefficient; "
        "units in the header). The result feeds design's --shear-strength and "
        "--work-of-adhesion.",
    )
    p.add_argument("friction_csv", help="the sphere's friction test, one row per normal force")
    p.add_argument("--sphere-radius", required=True, help="the sphere's radius, e.g. 5mm")
    p.add_argument("--modulus", required=True, help="equivalent modulus E*, e.g. 2.4MPa")
    p.add_argument("--out", help="also write the calibration as JSON here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from metainterface._files import strict_json
    from metainterface._files.atomic import write_text
    from metainterface.calibration import calibrate_csv

    cal = calibrate_csv(args.friction_csv, sphere_radius=args.sphere_radius, modulus=args.modulus)
    for line in cal.summary():
        print(line)
    if args.out:
        write_text(args.out, strict_json.dumps(cal.record(), indent=2) + "\n")
    return 0

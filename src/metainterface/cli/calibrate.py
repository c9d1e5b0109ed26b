"""`metainterface calibrate`: tau and w from a friction test of one sphere (JKR contact) or
of a made design (its cell under the adhesive model, given its design.json)."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "calibrate",
        help="fit the shear strength tau and work of adhesion w to a friction test of a "
        "sphere or of a made design",
        description="Fit tau and w, with their uncertainty, to a friction test of one sphere "
        "on the material (Bowden-Tabor friction F_f = tau A on a JKR contact), or of a made "
        "design (--design: its cell's real area under the adhesive model, load control). The "
        "CSV is a friction law (normal_force,friction_force in N, or "
        "normal_force,friction_coefficient; units in the header); a sphere test's pull rows "
        "(negative normal force, down to pull-off) are used. A test the model cannot explain "
        "(friction falling with load, a fit far outside the test's scatter, a range reaching "
        "tau <= 0 or w < 0) is refused: exit 2, nothing written. The result feeds design's "
        "--shear-strength and --work-of-adhesion.",
    )
    p.add_argument("friction_csv", help="the friction test, one row per normal force")
    what = p.add_mutually_exclusive_group(required=True)
    what.add_argument("--sphere-radius", help="a sphere test: the sphere's radius, e.g. 5mm")
    what.add_argument(
        "--design",
        help="a made design's test: its design.json (gammas, heights; R and the patch's "
        "area from its physical block)",
    )
    p.add_argument("--modulus", required=True, help="equivalent modulus E*, e.g. 2.4MPa")
    p.add_argument(
        "--area",
        help="with --design: the tested patch's nominal area, e.g. 4cm2 (default: the "
        "design.json's physical area)",
    )
    p.add_argument(
        "--radius",
        help="with --design: the asperity radius R, e.g. 0.5mm (default: the design.json's)",
    )
    p.add_argument(
        "--pull-off",
        help="a sphere test: the measured pull-off force, e.g. 0.92mN (its magnitude); it "
        "constrains w as one more row of the fit",
    )
    p.add_argument("--out", help="also write the calibration as JSON here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from metainterface._files import strict_json
    from metainterface._files.atomic import write_text
    from metainterface.calibration import calibrate_csv

    cal = calibrate_csv(
        args.friction_csv,
        modulus=args.modulus,
        sphere_radius=args.sphere_radius,
        design=args.design,
        area=args.area,
        radius=args.radius,
        pull_off=args.pull_off,
    )
    for line in cal.summary():
        print(line)
    if args.out:
        write_text(args.out, strict_json.dumps(cal.record(), indent=2) + "\n")
    return 0

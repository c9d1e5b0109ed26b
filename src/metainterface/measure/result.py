"""What ``mi.measure`` returns (:class:`MeasureResult`) and the files it writes."""

from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from metainterface.measure.compensate import Compensation, compensate, process_from
from metainterface.measure.predict import Prediction
from metainterface.measure.register import Registration
from metainterface.measure.report import measure_report, measure_warnings
from metainterface.measure.scan import Scan
from metainterface.physics.cell import Design


@dataclass(frozen=True)
class Friction:
    """The user's scale: modulus E* [Pa], shear strength tau [Pa], nominal area [m^2]."""

    modulus: float
    shear_strength: float
    area: float

    def forces(self, p_star: np.ndarray, alpha: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(normal force, friction force) [N] of a curve (K,)."""
        from metainterface.units import alpha_to_friction

        return alpha_to_friction(
            p_star,
            alpha,
            shear_strength=self.shear_strength,
            e_star=self.modulus,
            area=self.area,
        )


@dataclass(frozen=True)
class MeasureResult:
    """A made part measured: ``registration`` (lattice, tilt, fitted asperities),
    ``prediction`` (BEM and fitted-model curves, errors to the target), the scan and the
    design; ``friction`` where a modulus, shear strength and area were given;
    ``compensation`` where ``measure(..., compensate=True)`` made it.

    Lengths in the result's tables are in micrometres at the scan's R.
    """

    scan: Scan
    design: Design
    registration: Registration
    prediction: Prediction
    friction: Friction | None = None
    compensation: Compensation | None = None

    @property
    def error(self) -> float:
        """The made part's curve error to the target, by BEM on the measured cell."""
        return self.prediction.error_bem

    @property
    def p_star(self) -> np.ndarray:
        return self.prediction.p_star

    @property
    def alpha_bem(self) -> np.ndarray:
        return self.prediction.alpha_bem

    def __repr__(self) -> str:
        r, p = self.registration, self.prediction
        return (
            f"MeasureResult({int(r.seen.sum())} asperities fitted in {self.scan.source}, "
            f"rotation {math.degrees(r.lattice.theta):.3g} deg; made error "
            f"{100 * p.error_bem:.3g} % +- {100 * p.error_accuracy:.2g} % (BEM), "
            f"{100 * p.error_fit:.3g} % (fitted model); "
            f"design {100 * p.error_design:.3g} %{self._compensated()})"
        )

    def _compensated(self) -> str:
        c = self.compensation
        if c is None:
            return ""
        if c.printed is None:
            return "; no correction improves the made part"
        return (
            f"; compensated print: made error {100 * c.error_before:.3g} % -> "
            f"{100 * c.error_after:.3g} % (BEM of the predicted made cell)"
        )

    def compensate(
        self, *others: MeasureResult, model: Any = None, z_step: Any = None
    ) -> Compensation:
        """The geometry to print so that the made part meets the target: the process
        modelled from this result (and ``others``, more scans of the same print: their maps
        and shapes join), the design pre-distorted for it and checked in BEM on its
        predicted made cell (``measure.compensate``). z_step: the printer's layer step
        (e.g. "1um") where known."""
        z = None
        if z_step is not None:
            from metainterface.units import parse_length

            z = parse_length(z_step, option="z_step") / self.scan.radius_m
        triples = [(m.design, m.registration, m.prediction.shapes) for m in (self, *others)]
        return compensate(
            self.design,
            process_from(triples, z_step=z),
            model=model,
            grid=self.prediction.grid,
            loads=len(self.prediction.p_star),
            radius_m=self.scan.radius_m,
        )

    def warnings(self) -> list[str]:
        """Everything a user should know before trusting the figures, one line each."""
        return measure_warnings(self)

    def report(self, max_error: float | None = None) -> str:
        """The summary a user reads on screen: the made error from BEM with its accuracy,
        the orientation found, the worst asperities in um, every warning, the correction."""
        return measure_report(self, max_error)

    # --- reports -------------------------------------------------------------------------

    def asperities(self) -> list[dict[str, Any]]:
        """Per asperity k: made vs designed, in um and as share of the curve error."""
        r, p, d = self.registration, self.prediction, self.design
        um = 1e6 * self.scan.radius_m
        h_design = d.h - d.h.min()
        rows = []
        for k in range(d.n_asperities):
            rows.append(
                {
                    "k": k,
                    "cells_seen": int(r.seen[k]),
                    "gamma_design": float(d.gamma[k]),
                    "gamma_made": float(r.gamma[k]),
                    "gamma_spread": float(r.gamma_spread[k]),
                    "h_design_um": float(h_design[k] * um),
                    "h_made_um": float(r.h[k] * um),
                    "h_deviation_um": float((r.h[k] - h_design[k]) * um),
                    "h_spread_um": float(r.h_spread[k] * um),
                    "shift_x_um": float(r.shift[k, 0] * um),
                    "shift_y_um": float(r.shift[k, 1] * um),
                    "tip_radius_um": _finite(r.tip_radius[k] * um),
                    "tip_radius_design_um": _finite(r.tip_radius_design[k] * um),
                    "error_alone": float(p.error_alone[k]),
                    "error_share": float(p.share[k]),
                }
            )
        return rows

    def instances(self) -> list[dict[str, Any]]:
        """Every fitted asperity of every cell: its cell (column, row), index k, exponent,
        tip height (plane removed, aligned as ``h``) and lateral shift in um, fit residual."""
        r, um = self.registration, 1e6 * self.scan.radius_m
        f = r.fits
        d = self.design
        # the alignment of register: made h = -z0 - offset, the mean over asperities kept
        offset = np.mean(
            -np.bincount(f.kind, f.z0, d.n_asperities)[r.seen > 0] / r.seen[r.seen > 0]
        ) - np.mean(r.h[r.seen > 0])
        return [
            {
                "cell": [int(f.cell[i, 0]), int(f.cell[i, 1])],
                "k": int(f.kind[i]),
                "gamma": float(f.gamma[i]),
                "h_um": float((-f.z0[i] - offset) * um),
                "shift_x_um": float(f.shift[i, 0] * um),
                "shift_y_um": float(f.shift[i, 1] * um),
                "rms_um": float(f.rms[i] * um),
                "covered": float(min(1.0, f.cover[i])),
            }
            for i in range(f.kind.size)
        ]

    def summary(self) -> dict[str, Any]:
        r, p = self.registration, self.prediction
        um = 1e6 * self.scan.radius_m
        out = {
            "format": "metainterface/measured-v1",
            "scan": self.scan.source,
            "radius_m": self.scan.radius_m,
            "scan_points": list(self.scan.shape),
            "missing_points": self.scan.missing,
            "pixel_um": [self.scan.dx * um, self.scan.dy * um],
            "lattice": {
                **{
                    k: v * um if k.startswith(("origin", "pitch", "design_pitch")) else v
                    for k, v in r.lattice.to_dict().items()
                },
                "units": "um, degrees",
            },
            "tilt": [float(t) for t in r.tilt],
            "explained_variance": r.explained,
            "asperities_fitted": int(r.seen.sum()),
            "orientation": r.orientation.to_dict(),
            "error_bem": p.error_bem,
            "error_bem_accuracy": p.error_accuracy,
            "error_bem_read": (
                f"the BEM curve at {len(p.p_star)} loads over the target's range against the "
                f"target there; accuracy: its difference from the same on {p.grid_coarse}^2"
            ),
            "resolved_from_p_star": p.resolved_from,
            "error_fit": p.error_fit,
            "error_design": p.error_design,
            "coverage": p.coverage_fit,
            "bem_grid": int(p.grid),
            "bem_grid_coarse": int(p.grid_coarse),
            "shapes": self._shapes(),
            "warnings": self.warnings(),
            "bem_filled_share": p.cell.filled,
            "disagree_p_star": [float(v) for v in p.p_star[p.disagree]],
            "asperities": self.asperities(),
            "cells": self.instances(),
            "fitted_map": {
                "gamma": [float(v) for v in r.gamma],
                "h": [float(v) for v in r.h],
                "units": "h in units of R (as a design file)",
            },
        }
        if np.any(p.disagree):
            out["disagreement"] = next(w for w in self.warnings() if "not all power laws" in w)
        c = self.compensation
        if c is not None:
            out["compensation"] = {
                "written": c.printed is not None,
                "predicted_made_error_before": c.error_before,
                "predicted_made_error_after": c.error_after,
                "family_error_after": c.error_family,
                "process": c.process.to_dict(self.scan.radius_m),
                "limits": c.limits,
            }
        return out

    def _axes(self, um: float) -> tuple[np.ndarray, np.ndarray]:
        """The design's cell axes in the scan [um]: an origin near the scan's centre and
        the ends of u and v, a quarter of the scan long."""
        lat = self.registration.lattice
        w, h = self.scan.size
        u0, v0 = lat.to_cell(np.array(0.5 * w), np.array(0.5 * h))
        length = 0.25 * min(w, h) / lat.scale
        pts = [lat.to_scan(u0 + a, v0 + b) for a, b in ((0, 0), (length, 0), (0, length))]
        xy = np.array([[float(x), float(y)] for x, y in pts]) * um
        return xy[0], xy[1:]

    def _shapes(self) -> dict[str, Any]:
        sh = self.prediction.shapes
        um = 1e6 * self.scan.radius_m
        t = sh.terraces
        return {
            "noise_um": sh.noise * um,
            "cell_noise_um": sh.cell_noise * um,
            "layer_step_um": None if t is None else t.step * um,
            "layer_phase_um": None if t is None else t.phase * um,
            "layer_coherence": None if t is None else t.coherence,
            "flat_tip_radius_um": [float(v * um) for v in sh.flat_radius],
            "features": sh.feature,
            "restored": sh.restored(),
        }

    def bem_table(self) -> str:
        """bem.csv: a '# ' provenance line, then p_star, alpha_bem, alpha_bem_coarse,
        alpha_target, alpha_fit, alpha_design (+ forces in N)."""
        from metainterface._files.provenance import csv_header

        p = self.prediction
        cols: dict[str, np.ndarray] = {
            "p_star": p.p_star,
            "alpha_bem": p.alpha_bem,
            "alpha_bem_coarse": p.alpha_coarse,
            "alpha_target": p.alpha_target,
            "alpha_fit": p.alpha_fit,
            "alpha_design": p.alpha_design,
        }
        if self.friction is not None:
            fn, ff = self.friction.forces(p.p_star, p.alpha_bem)
            cols["normal_force_N"], cols["friction_N"] = fn, ff
        buf = io.StringIO()
        buf.write(
            csv_header(
                command="measure",
                scan=self.scan.source,
                scan_sha256=_array_hash(self.scan.heights),
                design=self.design.to_dict(),
                radius_m=self.scan.radius_m,
                grid=int(p.grid),
                loads=len(p.p_star),
            )
        )
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(cols)
        for row in zip(*cols.values(), strict=True):
            w.writerow([f"{v:.10g}" for v in row])
        return buf.getvalue()

    def write(
        self,
        folder: str | os.PathLike[str],
        *,
        compensate: bool | Compensation | None = None,
    ) -> list[Path]:
        """measured.json, bem.csv, measured.png in ``folder``, each written atomically; and
        compensated.json (a design file: the geometry to print next) with ``compensate``
        (True: ``self.compensate()``; or a Compensation already made; None: this result's
        ``compensation`` if it has one). Returns the paths."""
        from metainterface._files import strict_json
        from metainterface._files.atomic import atomic_path, check_output_folder, write_text

        if compensate is None:
            compensated = self.compensation
        elif compensate is True:
            compensated = self.compensate()
        else:
            compensated = compensate or None
        folder = check_output_folder(folder)
        folder.mkdir(parents=True, exist_ok=True)
        out = [
            write_text(
                folder / "measured.json", strict_json.dumps(self.summary(), indent=2) + "\n"
            ),
            write_text(folder / "bem.csv", self.bem_table()),
        ]
        fig = self.figure()
        with atomic_path(folder / "measured.png") as tmp:
            fig.savefig(tmp, format="png", dpi=110)
        import matplotlib.pyplot as plt

        plt.close(fig)
        out.append(folder / "measured.png")
        if isinstance(compensated, Compensation) and compensated.printed is not None:
            out.append(compensated.printed.save(folder / "compensated.json"))
        return out

    def figure(self):
        """Scan, designed map, difference, predicted law against the target."""
        from metainterface.plots.measure import measure_figure

        r, p, d = self.registration, self.prediction, self.design
        um = 1e6 * self.scan.radius_m
        from metainterface.measure.fit import levelled
        from metainterface.measure.surface import lattice_surface

        x, y = np.meshgrid(*self.scan.coords())
        u, v = r.lattice.to_cell(x, y)
        designed = lattice_surface(u, v, -(d.h - d.h.min()), d.gamma, d.settings)
        scan = levelled(self.scan, r.tilt)
        shift = np.nanmedian(scan - designed)
        return measure_figure(
            scan=(scan - shift) * um,
            designed=designed * um,
            extent=(0, self.scan.size[0] * um, 0, self.scan.size[1] * um),
            p_star=p.p_star,
            alpha_bem=p.alpha_bem,
            alpha_fit=p.alpha_fit,
            target=p.target,
            error_bem=p.error_bem,
            error_design=p.error_design,
            orientation=(
                f"turned {math.degrees(r.lattice.theta):.3g} deg"
                + (", mirrored (y reversed)" if r.orientation.mirrored else "")
            ),
            lattice=self._axes(um),
            to_forces=None if self.friction is None else self.friction.forces,
        )


def _array_hash(a: np.ndarray) -> str:
    import hashlib

    digest = hashlib.sha256(np.ascontiguousarray(a, dtype=np.float64).tobytes()).hexdigest()
    return "sha256:" + digest[:16]


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None

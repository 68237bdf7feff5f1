"""Generated road profiles against the ISO 8608 class values."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cosim.core.roughness import N0, N_MAX, N_MIN, averaged_psd, iso8608_band, iso8608_gd0, iso8608_profile

from ..results import CaseResult, FigureData, StudyResult, judge
from .common import TOL_ROUGHNESS

__all__ = [
    "RoughnessFigure",
    "iso8608_roughness",
]


@dataclass(frozen=True)
class RoughnessFigure(FigureData):
    """Third-octave PSDs (m^3) of generated profiles with their ISO 8608 class values and bands."""

    n0: float
    n_range: tuple[float, float]
    road_classes: tuple[str, ...]
    seeds: tuple[int, ...]
    class_values: tuple[float, ...]
    bands: tuple[tuple[float, float], ...]
    centres: tuple[npt.NDArray[np.float64], ...]
    psd: tuple[npt.NDArray[np.float64], ...]


def iso8608_roughness(length: float) -> StudyResult:
    """Generated road profiles of classes A and C: their PSD against the ISO 8608 class values."""
    # Third-octave bands over the classification range of ISO 8608 (0.011 to 2.83 cycle/m).
    edges = (0.011 * 2.0 ** (np.arange(0, 25) / 3.0)).tolist()
    file = "roughness_psd.png"
    cases, classes, seeds, gd0s, bands, centres_all, psds = [], [], [], [], [], [], []
    for road_class, seed in (("A", 1), ("C", 2)):
        profile = iso8608_profile(road_class, seed, 0.0, length)
        r = profile.r[0, :-1]  # one period (the last point repeats the first)
        centres, psd = averaged_psd(r, profile.dx, edges)
        # Least-squares fit of log G_d = log G_d(n0) - 2 log(n / n0) (ISO 8608 classification, waviness 2).
        gd_fit = float(np.exp(np.mean(np.log(psd * (centres / N0) ** 2))))
        slope = float(np.polyfit(np.log(centres), np.log(psd), 1)[0])
        gd0 = iso8608_gd0(road_class)
        lo, hi = iso8608_band(road_class)
        error = abs(gd_fit / gd0 - 1.0)
        inside = lo <= gd_fit <= hi
        classes.append(road_class)
        seeds.append(seed)
        gd0s.append(gd0)
        bands.append((lo, hi))
        centres_all.append(centres)
        psds.append(psd)
        cases.append(CaseResult(
            name=f"ISO 8608 roughness PSD, class {road_class}",
            reference="ISO 8608: G_d(n) = G_d(n0) (n/n0)^-2, n0 = 0.1 cycle/m, "
                      "class value the geometric mean of its band",
            metric="abs(fitted G_d(n0) / class value - 1) (least squares over third-octave bands, waviness 2); "
                   "the fit must also lie inside the class band",
            error=error, tolerance=TOL_ROUGHNESS, passed=judge(error, TOL_ROUGHNESS) and inside, figures=(file,),
            details=(f"Profile {length:g} m, dx = {profile.dx:g} m, seed {seed}: fitted G_d(n0) = {gd_fit:.4g} m3 "
                     f"(class value {gd0:.4g} m3, band {lo:.3g}-{hi:.3g} m3: {'inside' if inside else 'OUTSIDE'}), "
                     f"fitted waviness {-slope:.3f} (ISO: 2).",),
            values={"gd0_fit": gd_fit, "gd0_class": gd0, "band_low": lo, "band_high": hi, "waviness": -slope},
        ))
    figure = RoughnessFigure(file=file, n0=N0, n_range=(N_MIN, N_MAX), road_classes=tuple(classes),
                             seeds=tuple(seeds), class_values=tuple(gd0s), bands=tuple(bands),
                             centres=tuple(centres_all), psd=tuple(psds))
    return StudyResult(tuple(cases), (figure,))

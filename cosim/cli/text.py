"""Shared text of the command line: how scenarios, sections, modes, numbers and errors are printed."""
from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # only named here: importing this module must stay cheap (cosim --help imports it)
    from cosim.core.bridge import BridgeModel, ModalResult
    from cosim.core.section import SectionProperties
    from cosim.run.scenario import Scenario

#: Exit statuses: done, the run (or a check) failed, bad input, interrupted (Ctrl-C).
EXIT_OK = 0
EXIT_RUN_FAILED = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130


def scenario_line(scenario: Scenario) -> str:
    """``Scenario: <name>``, with the file it came from unless it is a bundled one."""
    if scenario.source == scenario.title:  # a bundled scenario, named by its name
        return f"Scenario: {scenario.title}"
    return f"Scenario: {scenario.title} ({scenario.source})"


def _fixed(value: float, digits: int = 4) -> str:
    """Fixed-point text without a "-0.0000" for round-off below the last digit."""
    return f"{round(float(value), digits) + 0.0:.{digits}f}"


def section_lines(section: SectionProperties) -> list[str]:
    """The section constants, one per line, with their units."""
    return [
        f"Section: {section.source}",
        f"  A      = {section.A:.6g} m^2",
        f"  C      = (y, z) = ({_fixed(section.y_c)}, {_fixed(section.z_c)}) m   centroid",
        f"  S      = (y, z) = ({_fixed(section.y_s)}, {_fixed(section.z_s)}) m   shear centre",
        f"  I_y    = {section.I_y:.6g} m^4   (vertical bending)",
        f"  I_z    = {section.I_z:.6g} m^4   (lateral bending)",
        f"  I_yz   = {section.I_yz:.6g} m^4",
        f"  J      = {section.J:.6g} m^4   (St Venant torsion)",
        f"  I_w    = {section.I_w:.6g} m^6   (warping, about S)",
        f"  A_sy   = {section.A_sy:.6g} m^2   (lateral shear, k_y = {section.A_sy / section.A:.4f})",
        f"  A_sz   = {section.A_sz:.6g} m^2   (vertical shear, k_z = {section.A_sz / section.A:.4f})",
        f"  deck   = {section.deck_y[0]:g} m <= y <= {section.deck_y[1]:g} m",
    ]


def damping_lines(bridge: BridgeModel) -> list[str]:
    """The Rayleigh coefficients and how they were chosen (or "none")."""
    if bridge.alpha == 0 and bridge.beta == 0:
        return ["Damping: none (undamped)"]
    return [
        f"Damping: C = alpha M + beta K, alpha = {bridge.alpha:.6g} 1/s, beta = {bridge.beta:.6g} s",
        f"  {bridge.damping_note}",
    ]


def modes_lines(modal: ModalResult) -> list[str]:
    """A table of the modes: frequency, kind and effective modal mass fractions."""
    part = modal.participation
    lines = [
        "Modes (effective modal mass fractions)",
        f"  {'#':>3}  {'f [Hz]':>9}  {'kind':<28}{'vertical':>9}{'lateral':>9}{'torsion':>9}",
    ]
    for i, f in enumerate(modal.f_hz):
        fractions = "".join(f"{float(part[k][i]):9.3f}" if k in part else f"{'-':>9}"
                            for k in ("vertical", "lateral", "torsion"))
        lines.append(f"  {i + 1:>3}  {f:9.4f}  {modal.kinds[i]:<28}{fractions}")
    return lines


def print_lines(lines: Sequence[str]) -> None:
    """Print each line on stdout."""
    for line in lines:
        print(line)


def fmt_g(value: float, digits: int = 6) -> str:
    """``value`` with ``digits`` significant digits (``%g``)."""
    return f"{float(value):.{digits}g}"


def window_text(start: float | None, end: float | None) -> str:
    """`` from t = T0 to T1 s`` for a window of time given on the command line ("" for none)."""
    if start is None and end is None:
        return ""
    low = f"t = {fmt_g(start, 9)}" if start is not None else "the start"
    high = f"{fmt_g(end, 9)} s" if end is not None else "the end"
    if start is None:
        high = f"t = {high}"
    return f" from {low} to {high}"


def size_text(n: int) -> str:
    """A file size in B, kB, MB or GB (3 significant digits)."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n} B"


def report_error(message: str) -> None:
    """``cosim: error: <first line>`` on stderr, further lines indented below it."""
    lines = message.splitlines() or [""]
    print(f"cosim: error: {lines[0]}", file=sys.stderr)
    for line in lines[1:]:
        print(f"  {line}", file=sys.stderr)

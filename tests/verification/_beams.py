"""Section constants shared by the verification tests (explicit, so each closed form sees exactly them)."""
from __future__ import annotations

from cosim.section import Material, SectionProperties

STEEL = Material(E=210e9, G=80e9, rho=7850.0)


def rectangle(b: float, h: float, shear_factor: float = 5.0 / 6.0) -> SectionProperties:
    """Solid b x h rectangle (b lateral, h vertical), centroid and shear centre at the origin."""
    A = b * h
    return SectionProperties(
        A=A, y_c=0.0, z_c=0.0, I_y=b * h**3 / 12, I_z=h * b**3 / 12, I_yz=0.0, y_s=0.0, z_s=0.0,
        J=0.229 * h * b**3, I_w=0.0, A_sy=shear_factor * A, A_sz=shear_factor * A, deck_y=(-b / 2, b / 2),
    )


def doubly_symmetric(I_w: float = 2.0e-6, J: float = 1.0e-6) -> SectionProperties:
    """An I-like section with S = C, for pure torsion and bending checks."""
    A = 0.02
    return SectionProperties(
        A=A, y_c=0.0, z_c=0.0, I_y=5e-4, I_z=1e-4, I_yz=0.0, y_s=0.0, z_s=0.0,
        J=J, I_w=I_w, A_sy=0.5 * A, A_sz=0.5 * A, deck_y=(-0.3, 0.3),
    )


def monosymmetric(e_z: float = 0.1, stiff_vertical: bool = True) -> SectionProperties:
    """Mono-symmetric (channel with horizontal web) section: S lies e_z above C on the symmetry axis.

    Shear areas are made huge (Euler-Bernoulli limit) and, optionally, vertical
    bending very stiff, so that the lowest modes are the coupled lateral-torsional ones.
    """
    A = 0.01
    return SectionProperties(
        A=A, y_c=0.0, z_c=0.0, I_y=2e-3 if stiff_vertical else 4e-5, I_z=2e-5, I_yz=0.0, y_s=0.0, z_s=e_z,
        J=5e-7, I_w=1e-8, A_sy=1e4 * A, A_sz=1e4 * A, deck_y=(-0.2, 0.2),
    )

"""Materials and cross-section constants (docs/theory.md §2).

Section coordinates are the bridge's lateral ``y`` (positive to the left looking
along +x) and vertical ``z`` (up), in metres, relative to any origin; ``y = 0``
is the bridge axis used for lane offsets. The code finds the centroid ``C`` and
the shear centre ``S`` itself.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Hashable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Protocol

import numpy as np

from cosim.errors import ConfigError, ModelError

from .checks import finite
from .limits import MAX_SECTION_TRIANGLES


@dataclass(frozen=True)
class Material:
    """Linear elastic isotropic material.

    Args:
        E: Young's modulus, Pa.
        G: shear modulus, Pa.
        rho: density, kg/m^3.
    """

    E: float
    G: float
    rho: float

    def __post_init__(self) -> None:
        for name in ("E", "G", "rho"):
            value = getattr(self, name)
            if not value > 0:
                raise ConfigError(f"`{name}` must be > 0 (got {value!r})")

    @property
    def nu(self) -> float:
        """Poisson's ratio implied by E and G (isotropy), dimensionless."""
        return self.E / (2.0 * self.G) - 1.0


@dataclass(frozen=True)
class Plate:
    """One thin-walled plate: a straight midline segment with a thickness.

    Args:
        start: (y, z) of one end of the midline, m.
        end: (y, z) of the other end, m.
        thickness: plate thickness, m.
    """

    start: tuple[float, float]
    end: tuple[float, float]
    thickness: float


@dataclass(frozen=True)
class SectionProperties:
    """Cross-section constants (SI units), all in the section's (y, z) frame.

    Attributes:
        A: area, m^2.
        y_c, z_c: centroid C, m.
        I_y: second moment about the centroidal y axis, integral of (z - z_c)^2 dA, m^4
            (governs vertical bending).
        I_z: second moment about the centroidal z axis, integral of (y - y_c)^2 dA, m^4
            (governs lateral bending).
        I_yz: product of area, integral of (y - y_c)(z - z_c) dA, m^4.
        y_s, z_s: shear centre S, m.
        J: St Venant torsion constant, m^4.
        I_w: warping constant about S (principal sectorial coordinate), m^6.
        A_sy: shear area for a shear force along y (lateral), m^2.
        A_sz: shear area for a shear force along z (vertical), m^2.
        deck_y: lateral extent (y_min, y_max) of the deck, m; sensors and wheel
            paths must lie inside it.
        source: where the constants came from (for logs and reports).
        I_ws: warping shear constant about S, m^4 (secondary torsion stiffness
            ``G I_ws`` of shear-deformable warping, docs/theory.md §10.2); None when
            not known, infinite for a section without warping.
        mass_per_length: mass per unit length, kg/m, replacing ``rho A`` in the
            translational inertia (and its coupling with the twist); None: ``rho A``.
        rotary_inertia: whether the bending rotations carry inertia ``rho I_y``,
            ``rho I_z`` (False for a classical Euler-Bernoulli beam).
        stress_field: the section's finite-element mesh with the warping function and the
            shear stresses per unit force (:class:`SectionField`), for stress sensors;
            None for explicit constants (no geometry). Not part of equality.
    """

    A: float
    y_c: float
    z_c: float
    I_y: float
    I_z: float
    I_yz: float
    y_s: float
    z_s: float
    J: float
    I_w: float
    A_sy: float
    A_sz: float
    deck_y: tuple[float, float]
    source: str = "constants"
    I_ws: float | None = None
    mass_per_length: float | None = None
    rotary_inertia: bool = True
    stress_field: SectionField | None = field(default=None, compare=False, repr=False)

    @property
    def I_ps(self) -> float:
        """Polar second moment about the shear centre, m^4."""
        return self.I_y + self.I_z + self.A * ((self.y_s - self.y_c) ** 2 + (self.z_s - self.z_c) ** 2)

    @property
    def k_y(self) -> float:
        """Shear coefficient for lateral shear, A_sy / A."""
        return self.A_sy / self.A

    @property
    def k_z(self) -> float:
        """Shear coefficient for vertical shear, A_sz / A."""
        return self.A_sz / self.A


#: A point this far outside every triangle (in area coordinates) still counts as inside: a point on the boundary.
_INSIDE_TOLERANCE = 1e-6


@dataclass(frozen=True, eq=False)
class SectionField:
    """The section's finite-element mesh and the fields a stress sensor reads at a point (docs/theory.md §12).

    Kept from the section solve of :func:`section_from_plates`. The warping
    function is the principal sectorial coordinate ``omega`` of (1.3) with the
    sign of the displacement field (1.2), ``u_x = ... - omega psi``: the
    Saint-Venant warping function of sectionproperties moved to the Trefftz
    shear centre S, less its mean, with the sign reversed. The shear stresses per
    unit force (Saint-Venant torsion and the flexure solution) are
    sectionproperties' own, computed on first use.

    Attributes:
        nodes: (n, 2) node coordinates (y, z), m, in the section's frame.
        elements: (n_el, 6) node ids of the quadratic triangles (corners, then the mid-sides 1-2, 2-3, 3-1).
        omega: (n,) the principal sectorial coordinate about S at the nodes, m^2.
        solved: the solved ``sectionproperties`` Section (for the shear stresses).
        shear: :attr:`unit_shear` when it is known without ``solved`` (a section read back from a
            :class:`SectionStore`).
    """

    nodes: np.ndarray
    elements: np.ndarray
    omega: np.ndarray
    solved: Any = field(default=None, repr=False)
    shear: np.ndarray | None = field(default=None, repr=False)

    def locate(self, y: float, z: float) -> tuple[int, np.ndarray] | None:
        """The triangle holding the point (y, z) and the point's area coordinates there; None outside the section."""
        corners = self.nodes[self.elements[:, :3]]  # (n_el, 3, 2)
        a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
        det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        e2 = ((y - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (z - a[:, 1])) / det
        e3 = ((b[:, 0] - a[:, 0]) * (z - a[:, 1]) - (y - a[:, 0]) * (b[:, 1] - a[:, 1])) / det
        eta = np.stack([1.0 - e2 - e3, e2, e3], axis=1)
        best = int(np.argmax(eta.min(axis=1)))
        if not eta[best].min() >= -_INSIDE_TOLERANCE:
            return None
        return best, np.clip(eta[best], 0.0, 1.0)

    def contains(self, y: float, z: float) -> bool:
        """Whether (y, z), m, lies in the section (its boundary included)."""
        return self.locate(y, z) is not None

    def interpolate(self, values: np.ndarray, y: float, z: float) -> np.ndarray:
        """Nodal ``values`` (n, ...) interpolated at (y, z) with the quadratic triangles' shape functions.

        Raises:
            ConfigError: the point lies outside the section.
        """
        found = self.locate(y, z)
        if found is None:
            y_min, z_min = self.nodes.min(axis=0)
            y_max, z_max = self.nodes.max(axis=0)
            raise ConfigError(f"the point (y, z) = ({y:g}, {z:g}) m is not inside the section (which spans "
                              f"{y_min:g} <= y <= {y_max:g}, {z_min:g} <= z <= {z_max:g} m)")
        e, (e1, e2, e3) = found
        n = np.array([e1 * (2 * e1 - 1), e2 * (2 * e2 - 1), e3 * (2 * e3 - 1), 4 * e1 * e2, 4 * e2 * e3, 4 * e3 * e1])
        return np.tensordot(n, values[self.elements[e]], axes=1)

    def omega_at(self, y: float, z: float) -> float:
        """The principal sectorial coordinate at (y, z), m^2."""
        return float(self.interpolate(self.omega, y, z))

    @cached_property
    def unit_shear(self) -> np.ndarray:
        """(n, 3, 2): shear stresses (tau_xy, tau_xz) at the nodes, Pa, per unit St Venant torque (N m) and per
        unit shear force along y and along z (N): sectionproperties' Saint-Venant and flexure solutions."""
        if self.shear is not None:
            return self.shear
        stress = self.solved.calculate_stress(vx=1.0, vy=1.0, mzz=1.0).get_stress()[0]
        # sectionproperties' (x, y, z) are our (y, z, x): its sig_zx is our tau_xy, its sig_zy our tau_xz.
        out = np.empty((len(self.nodes), 3, 2))
        for k, load in enumerate(("mzz", "vx", "vy")):
            out[:, k, 0] = stress[f"sig_zx_{load}"]
            out[:, k, 1] = stress[f"sig_zy_{load}"]
        return out

    def shear_at(self, y: float, z: float) -> np.ndarray:
        """(3, 2): (tau_xy, tau_xz) at (y, z), Pa, per unit St Venant torque, unit V_y and unit V_z."""
        return np.asarray(self.interpolate(self.unit_shear, y, z))


# ---------------------------------------------------------------------------
# Input validation
# ---------------------------------------------------------------------------

def _point(value: object, name: str, where: str) -> tuple[float, float]:
    y: object
    z: object
    try:
        y, z = value  # type: ignore[misc]
    except (TypeError, ValueError):
        raise ConfigError(f"{where}`{name}` must be a (y, z) pair in m (got {value!r})") from None
    return finite(y, f"{name}[0]", where), finite(z, f"{name}[1]", where)


def validated_plates(plates: Sequence[Plate]) -> list[tuple[float, float, float, float, float]]:
    """Check every plate and lower it to ``(y1, z1, y2, z2, t)`` floats.

    Errors name the plate's index in ``plates`` so a user can find it in the
    scenario file.
    """
    if isinstance(plates, Plate):
        plates = [plates]
    if len(plates) == 0:
        raise ConfigError("a plate section needs at least one plate (got none)")
    rows = []
    for i, plate in enumerate(plates):
        where = f"plate {i}: "
        if not isinstance(plate, Plate):
            raise ConfigError(f"{where}expected a Plate(start, end, thickness) (got {plate!r})")
        y1, z1 = _point(plate.start, "start", where)
        y2, z2 = _point(plate.end, "end", where)
        t = finite(plate.thickness, "thickness", where)
        if not t > 0:
            raise ConfigError(f"{where}`thickness` must be > 0 (got {plate.thickness!r})")
        length = math.hypot(y2 - y1, z2 - z1)
        if not length > 0:
            raise ConfigError(
                f"{where}`start` and `end` coincide at {plate.start!r}: a plate needs a non-zero length"
            )
        rows.append((y1, z1, y2, z2, t))
    return rows


def _check_nu(nu: float) -> float:
    nu = finite(nu, "nu")
    # Isotropic stability bounds; the shear functions of the FE solver need them.
    if not -1.0 < nu < 0.5:
        raise ConfigError(f"`nu` must lie in (-1, 0.5) (got {nu!r})")
    return nu


def plate_rectangle(y1: float, z1: float, y2: float, z2: float, t: float) -> list[tuple[float, float]]:
    """Corners of the plate's rectangle: the midline offset by +-t/2, no end extension."""
    length = math.hypot(y2 - y1, z2 - z1)
    ny, nz = -(z2 - z1) / length * t / 2.0, (y2 - y1) / length * t / 2.0
    return [(y1 + ny, z1 + nz), (y2 + ny, z2 + nz), (y2 - ny, z2 - nz), (y1 - ny, z1 - nz)]


# ---------------------------------------------------------------------------
# Sections from plates: finite-element section solver (the model's values)
# ---------------------------------------------------------------------------

#: Number of finite-element section solves run in this process. Tests use it to
#: prove that the cache works; read it, never write it.
FE_SOLVES = 0

# The mesh default is a fraction of the thinnest plate's t^2 (the torsion and
# warping functions vary across the thickness, so the elements must be smaller
# than it), capped by a fraction of the total area so a single thick plate
# still gets a few hundred elements. At t_min^2/8 the paper's double-tee has
# about 1000 quadratic triangles, solves in ~0.5 s, and J is within ~0.1 % of
# the value at t_min^2/16.
_MESH_PER_T2 = 1.0 / 8.0
_MESH_PER_AREA = 1.0 / 500.0


def default_mesh_size(plates: Sequence[Plate]) -> float:
    """Default maximum triangle area for :func:`section_from_plates`, m^2.

    Args:
        plates: the section's plates.

    Returns:
        ``min(t_min**2 / 8, A / 500)`` with ``A = sum(b t)``, m^2.
    """
    rows = validated_plates(plates)
    t_min = min(r[4] for r in rows)
    area = sum(math.hypot(r[2] - r[0], r[3] - r[1]) * r[4] for r in rows)
    return min(_MESH_PER_T2 * t_min**2, _MESH_PER_AREA * area)


def _cache_key(rows: list[tuple[float, float, float, float, float]]) -> tuple:
    """Order-independent key: the union does not depend on plate order or direction."""
    plates = []
    for y1, z1, y2, z2, t in rows:
        a, b = sorted([(y1, z1), (y2, z2)])
        plates.append((a, b, t))
    return tuple(sorted(plates))


def section_from_plates(
    plates: Sequence[Plate], nu: float = 0.2, mesh_size: float | None = None, store: SectionStore | None = None
) -> SectionProperties:
    """Section constants of a plate assembly from the finite-element section solver.

    Each plate becomes the rectangle of its midline (length = segment length,
    no extension at the ends) and thickness; the rectangles are merged into one
    polygon and meshed with quadratic triangles, and ``sectionproperties``
    solves the Saint-Venant torsion and flexure problems on it. Closed cells
    are fine here (unlike :func:`cosim.validation.thin_walled.thin_walled_properties`).

    The solve is cached per process: the same plates (in any order or
    direction), ``nu`` and ``mesh_size`` return the stored result without
    solving again (see :data:`FE_SOLVES` and ``section_from_plates.cache_info()``);
    and between processes in ``store`` when one is given (scenarios use the
    user's cache folder, :mod:`cosim.run.section_cache`).

    Args:
        plates: midline segments with thicknesses, m, in section (y, z) coordinates.
        nu: Poisson's ratio, dimensionless; only the shear areas depend on it.
        mesh_size: maximum triangle area, m^2; default :func:`default_mesh_size`.
        store: solved sections kept between processes (:class:`SectionStore`); None solves in this process only.

    Returns:
        The section constants; ``source`` names the solver and mesh.

    Raises:
        ConfigError: a plate is invalid (the message names its index), the
            plates do not form one connected section, or ``nu``/``mesh_size``
            are out of range.
        ModelError: the section solver fails on the geometry.
    """
    rows = validated_plates(plates)
    nu = _check_nu(nu)
    given = mesh_size is not None
    if mesh_size is None:
        mesh_size = default_mesh_size(plates)
    else:
        mesh_size = finite(mesh_size, "mesh_size")
        if not mesh_size > 0:
            raise ConfigError(f"`mesh_size` must be > 0 m^2 (got {mesh_size!r})")
    # Bounded before meshing: the mesher and solver allocate per triangle (1e-5 m^2 on a deck: MemoryError).
    area = sum(math.hypot(r[2] - r[0], r[3] - r[1]) * r[4] for r in rows)
    MAX_SECTION_TRIANGLES.check(
        area / mesh_size, "`mesh_size`" if given else "`mesh_size` (the default, t_min^2 / 8)",
        f"about {area:.4g} m^2 of plates / {mesh_size:.3g} m^2 per triangle; a larger mesh_size makes fewer")
    try:
        return _solve_fe(_cache_key(rows), nu, mesh_size, store)
    except _Disconnected:
        _check_connected(rows)  # the message names the plates in the caller's order
        raise


def _rectangles_and_union(rows: list[tuple[float, float, float, float, float]]) -> tuple[list, Any]:
    """The plates' shapely rectangles and their union (a Polygon when connected)."""
    from shapely.geometry import Polygon
    from shapely.ops import unary_union

    rects = [Polygon(plate_rectangle(*r)) for r in rows]
    return rects, unary_union(rects)


class _Disconnected(Exception):
    """The plates of a solve are not one section (:func:`section_from_plates` says which, in the caller's order)."""


def _connected(rows: list[tuple[float, float, float, float, float]]) -> bool:
    from shapely.geometry import Polygon

    return isinstance(_rectangles_and_union(rows)[1], Polygon)


def _check_connected(rows: list[tuple[float, float, float, float, float]]) -> None:
    """Raise ConfigError naming the plates that do not touch plate 0's part."""
    from shapely.geometry import Polygon

    rects, union = _rectangles_and_union(rows)
    if isinstance(union, Polygon):
        return
    parts = list(getattr(union, "geoms", []))
    first = next((p for p in parts if p.intersection(rects[0]).area > 0), None)
    loose = [i for i, r in enumerate(rects) if first is None or not first.intersection(r).area > 0]
    raise ConfigError(
        "plates do not form one connected section: "
        + ", ".join(f"plate {i}" for i in loose)
        + " not connected to plate 0 (rectangles must overlap along an edge, not meet at a point)"
    )


class SectionStore(Hashable, Protocol):
    """Solved plate sections kept between processes (a cache): what :func:`section_from_plates` asks before solving.

    ``definition`` is the section's whole definition as text (the plates in a canonical order, ``nu`` and the mesh
    size, floats in hexadecimal: :func:`section_definition`). A store returns exactly what was saved for it, or None;
    it must never return a section it cannot vouch for (corrupt, another definition's). Stores are hashable values.
    The numerical core holds no store of its own: files and folders belong to the layers above
    (:class:`cosim.run.section_cache.SectionCache`).
    """

    def load(self, definition: str) -> SectionProperties | None:
        """The section saved for ``definition``, or None."""
        ...

    def save(self, definition: str, section: SectionProperties) -> None:
        """Keep a solved section (with its stress field) for ``definition``; a store that cannot, skips it."""
        ...


def section_definition(key: tuple, nu: float, mesh_size: float) -> str:
    """A plate section's definition as text, for a :class:`SectionStore` (the same for the same solve)."""
    plates = [(float(a[0]).hex(), float(a[1]).hex(), float(b[0]).hex(), float(b[1]).hex(), float(t).hex())
              for a, b, t in key]
    return repr(("plates", plates, "nu", float(nu).hex(), "mesh_size", float(mesh_size).hex()))


@functools.lru_cache(maxsize=128)
def _solve_fe(key: tuple, nu: float, mesh_size: float, store: SectionStore | None = None) -> SectionProperties:
    """The solved section: from ``store`` when it holds it, else solved (and saved there)."""
    definition = section_definition(key, nu, mesh_size) if store is not None else ""
    if store is not None:
        kept = store.load(definition)
        if kept is not None:
            return kept
    solved = _solve_fe_now(key, nu, mesh_size)
    if store is not None:
        store.save(definition, solved)
    return solved


def _solve_fe_now(key: tuple, nu: float, mesh_size: float) -> SectionProperties:
    global FE_SOLVES
    # Imported here: sectionproperties pulls in matplotlib (~1 s), which modules
    # that only need Material or constants should not pay for.
    from sectionproperties.analysis.section import Section
    from sectionproperties.pre.geometry import Geometry
    from sectionproperties.pre.pre import Material as SpMaterial

    rows = [(a[0], a[1], b[0], b[1], t) for a, b, t in key]
    # Checked here, not before a store's answer (a stored section was solved, so connected; shapely stays unloaded).
    if not _connected(rows):
        raise _Disconnected
    _, polygon = _rectangles_and_union(rows)
    # E = 1 makes the modulus-weighted getters return the geometric constants
    # while the material still carries nu, which the shear areas depend on.
    material = SpMaterial(
        name="unit", elastic_modulus=1.0, poissons_ratio=nu, yield_strength=1.0, density=1.0, color="w"
    )
    FE_SOLVES += 1
    try:
        geometry = Geometry(polygon.simplify(0.0), material=material)
        geometry.create_mesh(mesh_sizes=mesh_size)
        section = Section(geometry)
        section.calculate_geometric_properties()
        section.calculate_warping_properties()
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        raise ModelError(f"the section solver failed on the plate geometry: {exc}") from exc

    # sectionproperties' (x, y) are our (y, z); its I_xx is about the
    # horizontal axis, i.e. our I_y.
    area = float(section.get_ea())
    y_c, z_c = (float(v) for v in section.get_c())
    ixx, iyy, ixy = (float(v) for v in section.get_eic())
    # Shear centre: Trefftz's definition (get_sc_t), not the elasticity one
    # (get_sc). Trefftz's point is the centre of twist, independent of nu, and
    # the pole about which the sectorial products vanish -- exactly the S of
    # the Vlasov element (principal sectorial coordinate normalised at S). The
    # elasticity shear centre moves with nu (by 4.6 mm for the asymmetric
    # paper double-tee at nu = 0.2).
    y_st, z_st = (float(v) for v in section.get_sc_t())
    y_se, z_se = (float(v) for v in section.get_sc())
    # sectionproperties evaluates the warping constant with the elasticity
    # shear centre: gamma = I_ww - Q_w^2/A - y_se I_xw + x_se I_yw (centroidal
    # axes). Re-evaluate it at the Trefftz centre so I_w and S belong to the
    # same pole; I_xw, I_yw follow from the Trefftz formulas
    #   x_st D = I_xy I_xw - I_yy I_yw,  y_st D = I_xx I_xw - I_xy I_yw.
    det = ixx * iyy - ixy**2
    xs, ys = y_st - y_c, z_st - z_c
    i_xw, i_yw = np.linalg.solve(np.array([[ixy, -iyy], [ixx, -ixy]]), np.array([xs * det, ys * det]))
    gamma = float(section.get_egamma() + ((z_se - z_c) - ys) * i_xw - ((y_se - y_c) - xs) * i_yw)
    a_sx, a_sy = (float(v) for v in section.get_eas())
    i_w = max(gamma, 0.0)
    i_ws = _warping_shear_constant(section, (xs, ys), i_w, ixx + iyy + area * (xs**2 + ys**2))
    stress_field = _section_field(section, (xs, ys))
    y_min, _, y_max, _ = polygon.bounds
    return SectionProperties(
        A=area,
        y_c=y_c,
        z_c=z_c,
        I_y=ixx,
        I_z=iyy,
        I_yz=ixy,
        y_s=y_st,
        z_s=z_st,
        J=float(section.get_ej()),
        # Sections with next to no warping (a thin tee or cross) can come out at -1e-18.
        I_w=i_w,
        A_sy=a_sx,
        A_sz=a_sy,
        deck_y=(float(y_min), float(y_max)),
        source=(
            f"plates (sectionproperties FE, mesh {len(section.elements)} quadratic triangles "
            f"<= {mesh_size:.3g} m^2, nu = {nu:g})"
        ),
        I_ws=i_ws,
        stress_field=stress_field,
    )


def _section_field(section: Any, pole: tuple[float, float]) -> SectionField:
    """The mesh and the principal sectorial coordinate about the pole P (relative to C) at its nodes.

    sectionproperties' Saint-Venant warping function ``Phi_C`` (twist about C,
    ``u_x = theta' Phi``) moves to P as ``Phi_P = Phi_C - z_P y + y_P z``
    (docs/theory.md §12.1); the sectorial coordinate of (1.2) is ``-Phi_P`` less
    its mean (the mean weighted by the area: ``integral N_i dA`` per node).
    """
    from sectionproperties.analysis.fea import gauss_points

    cy, cz = (float(v) for v in section.get_c())
    coords = np.array([el.coords for el in section.elements], dtype=float)  # (n_el, 2, 6)
    ids = np.array([el.node_ids for el in section.elements], dtype=np.int64)
    nodes = np.zeros((section.num_nodes, 2))
    nodes[ids, 0], nodes[ids, 1] = coords[:, 0, :], coords[:, 1, :]
    y, z = nodes[:, 0] - cy, nodes[:, 1] - cz
    phi = np.asarray(section.section_props.omega, dtype=float) - pole[1] * y + pole[0] * z
    weights = np.zeros(len(nodes))
    for gp in gauss_points(n=6):
        n, _, jac = _tri6_gradients(coords - np.array([cy, cz])[None, :, None], gp[1:])
        np.add.at(weights, ids, gp[0] * jac[:, None] * n[None, :])
    omega = -(phi - (weights @ phi) / weights.sum())
    for array in (nodes, ids, omega):
        array.setflags(write=False)
    return SectionField(nodes=nodes, elements=ids, omega=omega, solved=section)


#: Below this share of I_ps^2 / A the warping constant is round-off (a section without warping): I_ws is infinite
#: (here and in the thin-walled formulas of :mod:`cosim.validation.thin_walled`).
NO_WARPING = 1e-12


def _tri6_gradients(coords: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shape functions (6,), their (y, z) gradients (n_el, 2, 6) and the area factors (n_el,) of Tri6 elements.

    ``coords`` (n_el, 2, 6) in the node order of sectionproperties (corners, then
    the mid-sides 1-2, 2-3, 3-1); ``eta`` one point in area coordinates. The
    same isoparametric map as ``sectionproperties.analysis.fea.shape_function``,
    vectorised over the elements.
    """
    e1, e2, e3 = eta
    n = np.array([e1 * (2 * e1 - 1), e2 * (2 * e2 - 1), e3 * (2 * e3 - 1), 4 * e1 * e2, 4 * e2 * e3, 4 * e3 * e1])
    dn = np.array([[4 * e1 - 1, 0, 0], [0, 4 * e2 - 1, 0], [0, 0, 4 * e3 - 1],
                   [4 * e2, 4 * e1, 0], [0, 4 * e3, 4 * e2], [4 * e3, 0, 4 * e1]])  # dN_i / d eta_k
    jac = np.ones((coords.shape[0], 3, 3))
    jac[:, 1:, :] = coords @ dn  # rows: 1, y, z against eta_k
    det = np.linalg.det(jac)
    # d eta / d(y, z): the last two columns of the inverse Jacobian.
    p = np.linalg.solve(jac, np.broadcast_to(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), (len(jac), 3, 2)))
    grad = np.einsum("ik,ekj->eji", dn, p)
    return n, grad, 0.5 * det


def _warping_shear_constant(section: Any, pole: tuple[float, float], i_w: float, i_ps: float) -> float:
    """Warping shear constant ``I_ws = I_w^2 / integral |grad F|^2 dA`` on the FE section mesh (docs/theory.md §10.2).

    Benscoter's warping stress ``sigma_x = -E omega psi'`` is balanced by shear
    stresses ``tau = (T_w / I_w) grad F`` with ``laplacian F = omega`` in the
    section and ``dF/dn = 0`` on its boundary (no traction), ``T_w`` the
    secondary torque. Their energy ``T_w^2 / (2 G I_ws)`` defines ``I_ws`` as the
    shear areas are defined. ``omega`` is the principal warping function about
    the Trefftz centre: sectionproperties' Saint-Venant function (twist about
    C) moved to that pole, less its mean. The Neumann problem is solved on the
    solver's own quadratic triangles with the mean of ``F`` held at zero (a
    Lagrange multiplier); 6-point quadrature integrates it exactly.

    Args:
        section: the solved ``sectionproperties`` Section.
        pole: the Trefftz shear centre relative to the centroid, m.
        i_w: the warping constant about that pole, m^6.
        i_ps: the polar moment about it, m^4 (only to judge "no warping").

    Returns:
        ``I_ws`` in m^4; infinite for a section without warping.
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    from sectionproperties.analysis.fea import gauss_points

    area = float(section.get_ea())
    if not i_w > NO_WARPING * i_ps**2 / area:
        return math.inf
    cy, cz = (float(v) for v in section.get_c())
    coords = np.array([el.coords for el in section.elements], dtype=float)  # (n_el, 2, 6)
    coords[:, 0, :] -= cy
    coords[:, 1, :] -= cz
    ids = np.array([el.node_ids for el in section.elements], dtype=np.int64)  # (n_el, 6)
    n_nodes = section.num_nodes
    y = np.zeros(n_nodes)
    z = np.zeros(n_nodes)
    y[ids], z[ids] = coords[:, 0, :], coords[:, 1, :]
    # The warping function about the pole P: omega_P = omega_C - z_P y + y_P z (then less its mean).
    omega = np.asarray(section.section_props.omega, dtype=float) - pole[1] * y + pole[0] * z

    k_el = np.zeros((len(ids), 6, 6))
    m_el = np.zeros((len(ids), 6, 6))
    c_el = np.zeros((len(ids), 6))
    for gp in gauss_points(n=6):
        n, grad, jac = _tri6_gradients(coords, gp[1:])
        weight = gp[0] * jac
        k_el += weight[:, None, None] * np.einsum("eki,ekj->eij", grad, grad)
        m_el += weight[:, None, None] * np.outer(n, n)[None]
        c_el += weight[:, None] * n[None]
    rows, cols = np.repeat(ids, 6, axis=1).ravel(), np.tile(ids, (1, 6)).ravel()
    stiffness = sp.csr_matrix((k_el.ravel(), (rows, cols)), shape=(n_nodes, n_nodes))
    mass = sp.csr_matrix((m_el.ravel(), (rows, cols)), shape=(n_nodes, n_nodes))
    ones = np.zeros(n_nodes)
    np.add.at(ones, ids, c_el)
    omega -= (ones @ omega) / area
    load = mass @ omega  # integral of N_i omega dA
    system = sp.bmat([[stiffness, ones[:, None]], [ones[None, :], None]], format="csc")
    f = spla.spsolve(system, np.append(load, 0.0))[:-1]
    energy = float(f @ load)  # integral of |grad F|^2 dA (F has zero mean and solves K F = load)
    if not (math.isfinite(energy) and energy > 0):
        raise ModelError("the section solver failed on the warping shear function (non-positive energy)")
    return i_w**2 / energy


section_from_plates.cache_info = _solve_fe.cache_info  # type: ignore[attr-defined]
section_from_plates.cache_clear = _solve_fe.cache_clear  # type: ignore[attr-defined]


# ---------------------------------------------------------------------------
# Sections from explicit constants
# ---------------------------------------------------------------------------

def section_from_constants(
    A: float,
    I_y: float,
    I_z: float,
    J: float,
    *,
    y_c: float = 0.0,
    z_c: float = 0.0,
    I_yz: float = 0.0,
    y_s: float | None = None,
    z_s: float | None = None,
    I_w: float = 0.0,
    A_sy: float | None = None,
    A_sz: float | None = None,
    deck_y: tuple[float, float] | None = None,
    source: str = "constants",
    I_ws: float | None = None,
    mass_per_length: float | None = None,
    rotary_inertia: bool = True,
) -> SectionProperties:
    """Section constants given directly (from a design report or another solver).

    Args:
        A: area, m^2.
        I_y: centroidal second moment for vertical bending, integral of (z - z_c)^2 dA, m^4.
        I_z: centroidal second moment for lateral bending, integral of (y - y_c)^2 dA, m^4.
        J: St Venant torsion constant, m^4.
        y_c, z_c: centroid, m.
        I_yz: centroidal product of area, m^4.
        y_s, z_s: shear centre, m; default the centroid (doubly symmetric section).
        I_w: warping constant about the shear centre, m^6; 0 ignores warping.
        A_sy, A_sz: shear areas for lateral / vertical shear, m^2; default 5/6 A
            (the solid-rectangle value, so give them for thin-walled sections).
        deck_y: lateral extent (y_min, y_max) of the deck, m; required.
        source: description kept with the constants.
        I_ws: warping shear constant about S, m^4 (needed by Benscoter torsion
            when ``I_w > 0``); default unknown.
        mass_per_length: mass per unit length, kg/m, replacing ``rho A`` in the
            translational inertia; default ``rho A``.
        rotary_inertia: False drops the inertia of the bending rotations
            (``rho I_y``, ``rho I_z``), as a classical Euler-Bernoulli beam has none.

    Returns:
        The validated constants.

    Raises:
        ConfigError: a value is missing, not finite or non-physical; the message
            names the key in backticks.
    """
    A = finite(A, "A")
    I_y = finite(I_y, "I_y")
    I_z = finite(I_z, "I_z")
    J = finite(J, "J")
    for name, value in (("A", A), ("I_y", I_y), ("I_z", I_z), ("J", J)):
        if not value > 0:
            raise ConfigError(f"`{name}` must be > 0 (got {value!r})")
    y_c = finite(y_c, "y_c")
    z_c = finite(z_c, "z_c")
    I_yz = finite(I_yz, "I_yz")
    # Positive definiteness of the centroidal inertia tensor: otherwise one
    # principal second moment is <= 0 and the bending stiffness is singular.
    if not I_y * I_z > I_yz**2:
        raise ConfigError(
            f"`I_yz` = {I_yz!r} m^4 is too large: I_y * I_z must exceed I_yz^2 "
            f"(I_y = {I_y!r}, I_z = {I_z!r}), or a principal second moment is <= 0"
        )
    y_sc: float = y_c if y_s is None else finite(y_s, "y_s")
    z_sc: float = z_c if z_s is None else finite(z_s, "z_s")
    I_w = finite(I_w, "I_w")
    if not I_w >= 0:
        raise ConfigError(f"`I_w` must be >= 0 (got {I_w!r})")
    shear: dict[str, float] = {}
    given: tuple[tuple[str, float | None], ...] = (("A_sy", A_sy), ("A_sz", A_sz))
    for name, area in given:
        shear[name] = 5.0 / 6.0 * A if area is None else finite(area, name)
        if not shear[name] > 0:
            raise ConfigError(f"`{name}` must be > 0 (got {area!r})")
    i_ws: float | None = None
    if I_ws is not None:
        i_ws = finite(I_ws, "I_ws")
        if not i_ws > 0:
            raise ConfigError(f"`I_ws` must be > 0 m^4 (got {I_ws!r})")
    mass: float | None = None
    if mass_per_length is not None:
        mass = finite(mass_per_length, "mass_per_length")
        if not mass > 0:
            raise ConfigError(f"`mass_per_length` must be > 0 kg/m (got {mass_per_length!r})")
    if not isinstance(rotary_inertia, bool):
        raise ConfigError(f"`rotary_inertia` must be true or false (got {rotary_inertia!r})")
    if deck_y is None:
        raise ConfigError("`deck_y` is required: the lateral extent [y_min, y_max] of the deck in m")
    y_min, y_max = _point(deck_y, "deck_y", "")
    if not y_min < y_max:
        raise ConfigError(f"`deck_y` must be ordered [y_min, y_max] with y_min < y_max (got {deck_y!r})")
    return SectionProperties(
        A=A, y_c=y_c, z_c=z_c, I_y=I_y, I_z=I_z, I_yz=I_yz, y_s=y_sc, z_s=z_sc, J=J, I_w=I_w,
        A_sy=shear["A_sy"], A_sz=shear["A_sz"], deck_y=(y_min, y_max), source=str(source),
        I_ws=i_ws, mass_per_length=mass, rotary_inertia=rotary_inertia,
    )

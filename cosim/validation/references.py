"""Closed-form and independent reference solutions (docs/theory.md §8, docs/validation.md).

The one copy of every reference the verification tests (``tests/verification``)
and ``cosim validate`` (:mod:`cosim.validation.cases`) compare the model with. Each
function names its source. numpy and scipy only.

Sign convention as in the model: ``z`` up, a load ``P < 0`` pushes down and
gives a negative deflection.
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.integrate import solve_ivp

from cosim.core.section import Material, SectionProperties
from cosim.errors import ConfigError, ModelError

__all__ = [
    "STEEL",
    "rectangle_torsion_constant",
    "rectangle_section",
    "doubly_symmetric_section",
    "monosymmetric_section",
    "ss_point_load_deflection",
    "cantilever_tip_load_deflection",
    "euler_bernoulli_ss_frequency_hz",
    "timoshenko_ss_frequency_hz",
    "midspan_torque_twist",
    "torsional_frequencies_hz",
    "benscoter_midspan_torque_twist",
    "benscoter_torsional_frequencies_hz",
    "i_section_warping_shear_constant",
    "channel_warping_shear_constant",
    "VBI2D_SPRUNG",
    "vbi2d_sprung_case",
    "lateral_torsional_frequencies_hz",
    "fryba_midspan_deflection",
    "sprung_mass_modal_solution",
]

# --------------------------------------------------------------------------- test sections

#: Structural steel of the verification beams.
STEEL = Material(E=210e9, G=80e9, rho=7850.0)


def rectangle_torsion_constant(b: float, h: float, terms: int = 50) -> float:
    """St Venant torsion constant (m^4) of a solid ``b`` x ``h`` rectangle, either side the longer.

    With ``a >= c`` the long and short sides (Timoshenko & Goodier, Theory of
    Elasticity, 3rd ed., 1970, sec. 109, the series of the Prandtl stress function)::

        J = (1/3) c^3 a [1 - (192 / pi^5) (c / a) sum_{n = 1, 3, 5, ...} tanh(n pi a / (2 c)) / n^5]

    ``J / (a c^3)`` is 0.1406 for a square, 0.2287 for 2:1, 0.2982 for 6:1 and
    tends to 1/3; ``terms`` odd terms leave a truncation below ``1e-8`` of ``J``.
    """
    if not (b > 0 and h > 0):
        raise ConfigError(f"the rectangle's sides must be > 0 m (got b = {b!r}, h = {h!r})")
    a, c = max(b, h), min(b, h)
    series = sum(np.tanh(n * np.pi * a / (2 * c)) / n**5 for n in range(1, 2 * terms, 2))
    return float(c**3 * a / 3 * (1 - 192 / np.pi**5 * c / a * series))


def rectangle_section(b: float, h: float, shear_factor: float = 5.0 / 6.0) -> SectionProperties:
    """Solid b x h rectangle (b lateral, h vertical, m), centroid and shear centre at the origin.

    ``shear_factor`` sets both shear areas ``k A``; a huge value removes shear
    flexibility (the Euler-Bernoulli / Rayleigh-beam limit). ``J`` is the exact
    series of :func:`rectangle_torsion_constant`; the warping constant is
    neglected (``I_w = 0``, small for a solid section).
    """
    A = b * h
    return SectionProperties(
        A=A, y_c=0.0, z_c=0.0, I_y=b * h**3 / 12, I_z=h * b**3 / 12, I_yz=0.0, y_s=0.0, z_s=0.0,
        J=rectangle_torsion_constant(b, h), I_w=0.0, A_sy=shear_factor * A, A_sz=shear_factor * A,
        deck_y=(-b / 2, b / 2),
    )


def doubly_symmetric_section(I_w: float = 2.0e-6, J: float = 1.0e-6) -> SectionProperties:
    """An I-like section with S = C (m^6, m^4), for pure torsion and bending checks."""
    A = 0.02
    return SectionProperties(
        A=A, y_c=0.0, z_c=0.0, I_y=5e-4, I_z=1e-4, I_yz=0.0, y_s=0.0, z_s=0.0,
        J=J, I_w=I_w, A_sy=0.5 * A, A_sz=0.5 * A, deck_y=(-0.3, 0.3),
    )


def monosymmetric_section(e_z: float = 0.1, stiff_vertical: bool = True) -> SectionProperties:
    """Mono-symmetric (channel with horizontal web) section: S lies ``e_z`` (m) above C on the symmetry axis.

    Shear areas are made huge (Euler-Bernoulli limit) and, optionally, vertical
    bending very stiff, so that the lowest modes are the coupled lateral-torsional ones.
    """
    A = 0.01
    return SectionProperties(
        A=A, y_c=0.0, z_c=0.0, I_y=2e-3 if stiff_vertical else 4e-5, I_z=2e-5, I_yz=0.0, y_s=0.0, z_s=e_z,
        J=5e-7, I_w=1e-8, A_sy=1e4 * A, A_sz=1e4 * A, deck_y=(-0.2, 0.2),
    )


# --------------------------------------------------------------------------- statics

def ss_point_load_deflection(
    x: npt.ArrayLike, a: float, L: float, P: float, EI: float, kGA: float
) -> npt.NDArray[np.float64]:
    """Deflection (m) of a simply supported Timoshenko beam under a point load ``P`` (N) at ``x = a``.

    Bending part (Gere & Timoshenko, Mechanics of Materials, table of beam
    deflections): ``P b x (L^2 - b^2 - x^2) / (6 EI L)`` for ``x <= a``,
    mirrored for ``x > a``; shear part: ``P b x / (kGA L)`` for ``x <= a`` and
    ``P a (L - x) / (kGA L)`` beyond. At the load: ``P a^2 b^2 / (3 EI L) + P a b / (kGA L)``.
    """
    x = np.asarray(x, dtype=float)
    b = L - a
    left = x <= a
    xr = L - x  # distance from the right support
    bending = np.where(
        left,
        P * b * x * (L**2 - b**2 - x**2) / (6 * EI * L),
        P * a * xr * (L**2 - a**2 - xr**2) / (6 * EI * L),
    )
    shear = np.where(left, P * b * x / (kGA * L), P * a * xr / (kGA * L))
    return bending + shear


def cantilever_tip_load_deflection(
    x: npt.ArrayLike, L: float, P: float, EI: float, kGA: float
) -> npt.NDArray[np.float64]:
    """Deflection (m) of a cantilever (fixed at x = 0) of Timoshenko type under a tip load ``P`` (N).

    ``P x^2 (3 L - x) / (6 EI) + P x / (kGA)``; at the tip ``P L^3 / (3 EI) + P L / (kGA)``
    (Timoshenko & Gere).
    """
    x = np.asarray(x, dtype=float)
    return P * x**2 * (3 * L - x) / (6 * EI) + P * x / kGA


# --------------------------------------------------------------------------- bending frequencies

def euler_bernoulli_ss_frequency_hz(n: npt.ArrayLike, L: float, EI: float, m: float) -> npt.NDArray[np.float64]:
    """``f_n = (n pi / L)^2 sqrt(EI / m) / (2 pi)``, Hz: simply supported Euler-Bernoulli beam, ``m`` per length."""
    n = np.asarray(n, dtype=float)
    return (n * np.pi / L) ** 2 * np.sqrt(EI / m) / (2 * np.pi)


def timoshenko_ss_frequency_hz(
    n: npt.ArrayLike, L: float, material: Material, section: SectionProperties
) -> npt.NDArray[np.float64]:
    """Vertical bending frequencies (Hz) of a simply supported Timoshenko beam, mode numbers ``n``.

    Smaller root of the frequency equation (Han, Benaroya & Wei, JSV 225, 1999):
    ``det [[kGA k^2 - rho A w^2, -kGA k], [-kGA k, EI k^2 + kGA - rho I w^2]] = 0``,
    ``k = n pi / L``, quadratic in ``w^2`` (shear ``A_sz``, inertia ``I_y``).
    """
    E, G, rho = material.E, material.G, material.rho
    k = np.asarray(n, dtype=float) * np.pi / L
    kga, ei = G * section.A_sz, E * section.I_y
    a = rho * section.A * rho * section.I_y
    b = -(rho * section.A * (ei * k**2 + kga) + rho * section.I_y * kga * k**2)
    c = kga * k**2 * (ei * k**2 + kga) - (kga * k) ** 2
    w2 = (-b - np.sqrt(b * b - 4 * a * c)) / (2 * a)
    return np.sqrt(w2) / (2 * np.pi)


# --------------------------------------------------------------------------- torsion

def midspan_torque_twist(
    x: npt.ArrayLike, L: float, T: float, GJ: float, EIw: float, warping: str
) -> npt.NDArray[np.float64]:
    """Twist (rad) of a beam under a torque ``T`` (N m) at mid-span, non-uniform (Vlasov) torsion.

    ``GJ theta' - E I_w theta''' = T/2`` on the left half, ``lambda = sqrt(GJ / (E I_w))``
    (Vlasov; Kollbrunner & Basler, Torsion in Structures, ch. 4), symmetric about mid-span:

    - ``warping="free"`` (theta = theta'' = 0 at the ends):
      ``theta = T/(2 GJ) (x - sinh(lambda x) / (lambda cosh(lambda L/2)))``,
      at mid-span ``T/(2 GJ) (L/2 - tanh(lambda L/2) / lambda)``;
    - ``warping="restrained"`` (theta = theta' = 0 at the ends):
      ``theta = T/(2 GJ) (x + tanh(lambda L/4) (cosh(lambda x) - 1) / lambda - sinh(lambda x) / lambda)``,
      at mid-span ``T/(2 GJ) (L/2 - 2 tanh(lambda L/4) / lambda)``.
    """
    x = np.asarray(x, dtype=float)
    s = np.minimum(x, L - x)
    lam = np.sqrt(GJ / EIw)
    if warping == "free":
        shape = s - np.sinh(lam * s) / (lam * np.cosh(lam * L / 2))
    elif warping == "restrained":
        shape = s + np.tanh(lam * L / 4) * (np.cosh(lam * s) - 1) / lam - np.sinh(lam * s) / lam
    else:
        raise ConfigError(f"`warping` must be 'free' or 'restrained' (got {warping!r})")
    return T / (2 * GJ) * shape


def torsional_frequencies_hz(
    n: npt.ArrayLike, L: float, material: Material, section: SectionProperties
) -> npt.NDArray[np.float64]:
    """Torsional frequencies (Hz) with fork supports (warping free), S = C.

    ``omega^2 = (GJ k^2 + E I_w k^4) / (rho I_p + rho I_w k^2)``, ``k = n pi / L``
    (Vlasov; docs/theory.md §8), polar inertia about the shear centre.
    """
    E, G, rho = material.E, material.G, material.rho
    k = np.asarray(n, dtype=float) * np.pi / L
    w2 = (G * section.J * k**2 + E * section.I_w * k**4) / (rho * section.I_ps + rho * section.I_w * k**2)
    return np.sqrt(w2) / (2 * np.pi)


# --------------------------------------------------------------------------- shear-deformable warping (Benscoter)

def benscoter_midspan_torque_twist(
    x: npt.ArrayLike, L: float, T: float, GJ: float, EIw: float, GIws: float, warping: str
) -> npt.NDArray[np.float64]:
    """Twist (rad) under a mid-span torque ``T`` (N m) with shear-deformable warping (Benscoter).

    Derived in docs/theory.md §10.4 from the equilibrium of the left half,
    ``GJ theta' + G I_ws (theta' - psi) = T/2`` and ``E I_w psi'' + G I_ws (theta' - psi) = 0``
    (Benscoter, J. Appl. Mech. 21, 1954), which give
    ``psi'' - mu^2 psi = -mu^2 T / (2 GJ)`` with ``mu^2 = GJ G I_ws / (E I_w (GJ + G I_ws))``,
    ``psi(L/2) = 0`` by symmetry, and::

        theta = T x / (2 G_t) + (G I_ws / G_t) T / (2 GJ) I(x),   G_t = GJ + G I_ws,

    with ``I = x - sinh(mu x)/mu + tanh(mu L/4) (cosh(mu x) - 1)/mu`` for warping
    restrained ends (theta = psi = 0) and ``I = x - sinh(mu x) / (mu cosh(mu L/2))``
    for fork ends (theta = 0, psi' = 0). ``G I_ws -> inf`` gives the Vlasov forms of
    :func:`midspan_torque_twist`.
    """
    x = np.asarray(x, dtype=float)
    s = np.minimum(x, L - x)
    g_t = GJ + GIws
    mu = np.sqrt(GJ * GIws / (EIw * g_t))
    if warping == "restrained":
        integral = s - np.sinh(mu * s) / mu + np.tanh(mu * L / 4) * (np.cosh(mu * s) - 1) / mu
    elif warping == "free":
        integral = s - np.sinh(mu * s) / (mu * np.cosh(mu * L / 2))
    else:
        raise ConfigError(f"`warping` must be 'free' or 'restrained' (got {warping!r})")
    return T * s / (2 * g_t) + GIws / g_t * T / (2 * GJ) * integral


def benscoter_torsional_frequencies_hz(
    n: npt.ArrayLike, L: float, material: Material, section: SectionProperties
) -> npt.NDArray[np.float64]:
    """Torsional frequencies (Hz) with shear-deformable warping, fork supports, S = C (docs/theory.md §10.4).

    ``theta = sin(k x)``, ``psi = cos(k x)`` (``k = n pi / L``) in the equations of
    motion of the energies (10.1)-(10.2) give the smaller root of::

        (G_t k^2 - w^2 rho I_ps)(E I_w k^2 + G I_ws - w^2 rho I_w) - (G I_ws k)^2 = 0,   G_t = GJ + G I_ws,

    the torsional counterpart of Timoshenko's frequency equation (Han, Benaroya
    & Wei 1999); ``I_ws -> inf`` gives :func:`torsional_frequencies_hz`.
    """
    if section.I_ws is None:
        raise ConfigError("the section has no warping shear constant `I_ws`")
    E, G, rho = material.E, material.G, material.rho
    k = np.asarray(n, dtype=float) * np.pi / L
    gj, eiw, giws = G * section.J, E * section.I_w, G * section.I_ws
    a = rho * section.I_ps * rho * section.I_w
    b = -(rho * section.I_ps * (eiw * k**2 + giws) + rho * section.I_w * (gj + giws) * k**2)
    c = (gj + giws) * k**2 * (eiw * k**2 + giws) - (giws * k) ** 2
    w2 = (-b - np.sqrt(b * b - 4 * a * c)) / (2 * a)
    return np.sqrt(w2) / (2 * np.pi)


def i_section_warping_shear_constant(b: float, h: float, t_f: float) -> float:
    """``I_ws = 5/12 b t_f h^2`` (m^4) of a doubly symmetric thin-walled I-section (docs/theory.md §10.2).

    Flange width ``b``, depth ``h`` between flange midlines: the secondary torque
    ``T_w`` is carried by the flanges' lateral shear forces ``+-T_w / h``, whose
    parabolic flows store the energy of a rectangle ``b t_f`` with the shear
    coefficient 5/6; the web carries none.
    """
    return 5.0 / 12.0 * b * t_f * h**2


def channel_warping_shear_constant(b: float, h: float, t_f: float, t_w: float) -> float:
    """``I_ws`` (m^4) of a thin-walled channel (flanges ``b`` from the web's midline, web ``h``) (docs/theory.md §10.2).

    ``I_w^2 / integral(S_w^2 / t ds)`` with the principal sectorial coordinate
    about the shear centre ``e = 3 b^2 t_f / (6 b t_f + h t_w)`` behind the web,
    ``I_w = t_f b^3 h^2 (3 b t_f + 2 h t_w) / (12 (6 b t_f + h t_w))``, integrated
    in closed form over the flanges and the web::

        I_ws = 5 b^2 h^2 t_f (3 b t_f + 2 h t_w)^2
               / (3 (36 b^3 t_f^2 + 42 b^2 h t_f t_w + 16 b h^2 t_w^2 + 3 h^3 t_f t_w))
    """
    numerator = 5 * b**2 * h**2 * t_f * (3 * b * t_f + 2 * h * t_w) ** 2
    denominator = 3 * (36 * b**3 * t_f**2 + 42 * b**2 * h * t_f * t_w + 16 * b * h**2 * t_w**2 + 3 * h**3 * t_f * t_w)
    return numerator / denominator


# --------------------------------------------------------------------------- coupled torsion

def lateral_torsional_frequencies_hz(
    n_max: int, L: float, material: Material, section: SectionProperties
) -> npt.NDArray[np.float64]:
    """Coupled lateral-torsional frequencies (Hz), ascending, of a mono-symmetric section with fork supports.

    Sine modes in ``v`` and ``theta_x`` for ``n = 1..n_max`` (two roots each), S a
    distance ``z_s`` from C on the symmetry axis (Timoshenko & Gere, Theory of
    Elastic Stability; Rayleigh beam: rotary inertia ``rho I_z k^2`` and warping
    inertia ``rho I_w k^2`` kept)::

        det([[EI_z k^4 - w^2 rho (A + I_z k^2), -w^2 rho A z_s],
             [-w^2 rho A z_s, GJ k^2 + E I_w k^4 - w^2 rho (I_ps + I_w k^2)]]) = 0
    """
    E, G, rho = material.E, material.G, material.rho
    out: list[float] = []
    for n in range(1, n_max + 1):
        k = n * np.pi / L
        k11, k22 = E * section.I_z * k**4, G * section.J * k**2 + E * section.I_w * k**4
        m11 = rho * (section.A + section.I_z * k**2)
        m22 = rho * (section.I_ps + section.I_w * k**2)
        m12 = rho * section.A * section.z_s
        w2 = np.roots([m11 * m22 - m12**2, -(k11 * m22 + k22 * m11), k11 * k22])
        out.extend(np.sqrt(np.sort(w2.real)) / (2 * np.pi))
    return np.sort(np.array(out))


# --------------------------------------------------------------------------- moving loads

def fryba_midspan_deflection(
    t: npt.ArrayLike, L: float, v: float, P: float, EI: float, m: float, n_modes: int = 80
) -> npt.NDArray[np.float64]:
    """Mid-span deflection (m, up positive) under a constant force ``P`` (N, downward) crossing at speed ``v``.

    Undamped simply supported Euler-Bernoulli beam, modal series (Fryba,
    Vibration of Solids and Structures under Moving Loads, 1972, ch. 1),
    valid while the force is on the beam (``0 <= t <= L / v``).
    """
    t = np.asarray(t, dtype=float)
    w = np.zeros_like(t)
    for n in range(1, n_modes + 1):
        wn = (n * np.pi / L) ** 2 * np.sqrt(EI / m)
        om = n * np.pi * v / L
        qn = 2 * P / (m * L) / (wn**2 - om**2) * (np.sin(om * t) - om / wn * np.sin(wn * t))
        w -= qn * np.sin(n * np.pi / 2)
    return w


def sprung_mass_modal_solution(
    t_eval: npt.ArrayLike,
    L: float,
    EI: float,
    m: float,
    m_v: float,
    k_v: float,
    c_v: float,
    v: float,
    gravity: float = 9.81,
    n_modes: int = 20,
    rtol: float = 1e-10,
    atol: float = 1e-13,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """A sprung mass crossing a simply supported Euler-Bernoulli beam: an independent modal solution.

    The Yang & Yau (1997) / Biggs type benchmark: body ``m_v`` on a spring
    ``k_v`` and damper ``c_v`` whose lower end follows the deck at the contact
    point ``x = v t``; ``n_modes`` mass-normalised sine modes of the continuous
    beam; the ODE is integrated by ``solve_ivp`` (DOP853). The body starts at
    its static equilibrium on a rigid road (displacements measured from it).

    Returns:
        Mid-span deflection (m, up positive) and body acceleration (m/s^2) at ``t_eval`` (s).
    """
    t_eval = np.asarray(t_eval, dtype=float)
    n = np.arange(1, n_modes + 1)
    wn = (n * np.pi / L) ** 2 * np.sqrt(EI / m)
    norm = np.sqrt(2 / (m * L))  # mass-normalised sine modes

    def rhs(t: float, s: np.ndarray) -> np.ndarray:
        q, qd, u, ud = s[:n_modes], s[n_modes:2 * n_modes], s[-2], s[-1]
        x = v * t
        phi = norm * np.sin(n * np.pi * x / L)
        phi_x = norm * n * np.pi / L * np.cos(n * np.pi * x / L)
        w, wd = phi @ q, phi @ qd + v * (phi_x @ q)
        f_dyn = k_v * (u - w) + c_v * (ud - wd)
        force = -m_v * gravity + f_dyn  # on the deck, up positive
        return np.concatenate([qd, -wn**2 * q + phi * force, [ud, -f_dyn / m_v]])

    span = (0.0, float(t_eval[-1]))
    sol = solve_ivp(rhs, span, np.zeros(2 * n_modes + 2), t_eval=t_eval, method="DOP853", rtol=rtol, atol=atol)
    if not sol.success:
        raise ModelError(f"the reference ODE solve failed: {sol.message}")
    w_mid = (norm * np.sin(n * np.pi / 2)) @ sol.y[:n_modes]
    body_acc = np.array([rhs(t, s)[-1] for t, s in zip(sol.t, sol.y.T)])
    return w_mid, body_acc


# Yang & Yau (1997) moving sprung mass: L 25 m, EI 2.943e10 N m2, m 2303 kg/m,
# sprung mass 5750 kg on k 1.595e6 N/m (no damping), 100 km/h.
YANG_YAU = {"L": 25.0, "EI": 2.943e10, "m": 2303.0, "m_v": 5750.0, "k_v": 1.595e6, "c_v": 0.0, "v": 27.78}


def yang_yau_case():
    """The Yang & Yau sprung-mass benchmark as a cosim model: (bridge, traffic, crossing time T).

    The section makes EI and m match with negligible rotary inertia (I/A =
    1e-3 m^2) and shear flexibility, so the Euler-Bernoulli modal reference
    (:func:`sprung_mass_modal_solution`) applies.
    """
    from cosim.core.bridge import build_bridge
    from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
    from cosim.core.vehicles import QuarterCar

    p = YANG_YAU
    mat = Material(E=p["EI"] / 1e-3, G=1e12, rho=p["m"])
    sec = SectionProperties(A=1.0, y_c=0, z_c=0, I_y=1e-3, I_z=1e-3, I_yz=0, y_s=0, z_s=0, J=1e-3, I_w=0,
                            A_sy=1e6, A_sz=1e6, deck_y=(-1.0, 1.0))
    bridge = build_bridge([p["L"]], 40, mat, sec, ["pinned", "fork"])
    car = QuarterCar(m_v=p["m_v"], m_w=0.0, k_v=p["k_v"], c_v=p["c_v"])
    traffic = ScriptedTraffic((ScriptedVehicle("S", car, 0.0, p["v"]),), p["L"])
    return bridge, traffic, p["L"] / p["v"]


# VBI-2D's sprung-vehicle verification case (D. Cantero, VBI-2D, github.com/DanielCanteroNTNU/VBI-2D,
# V01_Analytical_Verification_Examples.m, "SprungVeh"):
# L 25 m, E 3.5e10 Pa, I 1.3901 m^4, 18358 kg/m, undamped; body 5750 kg on 1.595e6 N/m, no damper and
# no wheel mass, 25 m/s, at x = 0 at t = 0; its modal Newmark solution (100 modes, dt 1 ms) peaks at mid-span
# at -0.41855 mm at t = 0.436 s.
VBI2D_SPRUNG = {"L": 25.0, "E": 3.5e10, "I": 1.3901, "m": 18358.0, "m_v": 5750.0, "k_v": 1.595e6, "v": 25.0,
                "peak_w": -0.41855e-3, "peak_t": 0.436}


def vbi2d_sprung_case(n_el: int = 20):
    """VBI-2D's sprung-vehicle case as a cosim model: (bridge, traffic, crossing time), Python API.

    The same model as ``examples/scenarios/vbi2d-sprung-mass.toml``: Euler-Bernoulli
    bending, the mass per length given, no rotary inertia; the body is a
    quarter-car without wheel mass; A, J, I_z and rho only set modes this 2D case
    does not excite.
    """
    from cosim.core.bridge import BeamTheory, build_bridge
    from cosim.core.section import section_from_constants
    from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle
    from cosim.core.vehicles import QuarterCar

    p = VBI2D_SPRUNG
    material = Material(E=p["E"], G=p["E"] / 2.4, rho=2500.0)
    section = section_from_constants(A=7.3432, I_y=p["I"], I_z=20.0, J=2.0, mass_per_length=p["m"],
                                     rotary_inertia=False, deck_y=(-2.5, 2.5))
    bridge = build_bridge([p["L"]], n_el, material, section, ["pinned", "fork"],
                          theory=BeamTheory(bending="euler-bernoulli"))
    car = QuarterCar(m_v=p["m_v"], m_w=0.0, k_v=p["k_v"], c_v=0.0)
    traffic = ScriptedTraffic((ScriptedVehicle("sprung", car, 0.0, p["v"]),), p["L"])
    return bridge, traffic, p["L"] / p["v"]

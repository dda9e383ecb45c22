"""Contact laws (LAMMPS-style "styles": one function each, one signature).

- ``LINEAR`` (PFC deformability): ``kn = A / (r_i/E_i + r_j/E_j)`` -- for equal moduli
  ``A E / (r_i + r_j)`` -- with ``A = 2 r_min t`` (2D) or ``pi r_min^2`` (3D);
  ``ks = kn / kratio``; normal and shear dashpots by critical damping ratios beta_n, beta_s.
- ``HERTZ`` (Hertz-Mindlin no-slip, as EDEM/LIGGGHTS): ``Fn = 4/3 E* sqrt(R*) d^1.5``,
  ``Sn = 2 E* sqrt(R* d)``, ``St = 8 G* sqrt(R* d)``, dashpots ``gamma sqrt(S m*)`` with
  gamma from the coefficient of restitution (``hertz_damping_from_cor``).
Both: Coulomb friction on a shear spring carried in the contact history, constant
directional torque (CDT) rolling friction ``mu_r Fn R*`` opposing relative rolling.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from tribodem.dem.jit import kernel
from tribodem.dem.space import min_image

LINEAR = 0
HERTZ = 1
LAWS = {"linear": LINEAR, "hertz": HERTZ}

# columns of the pair property table pairtab[mat_a, mat_b, :]
P_LAW, P_ESTAR, P_GSTAR, P_MU, P_MUR, P_GAMMA, P_KRATIO, P_BETAN, P_BETAS = range(9)
N_PROPS = 9
HIST = 3  # history per contact: shear spring displacement (m), 3 components


@dataclass
class Material:
    """Particle or wall material (SI).

    ``young``/``poisson`` feed Hertz-Mindlin; ``effective_modulus`` (PFC E_c, default
    ``young``) and ``kratio`` feed the linear law. ``cor`` is the coefficient of
    restitution (Hertz); ``beta_n``/``beta_s`` are critical damping ratios (linear).
    """

    name: str = "material"
    young: float = 2.0e11
    poisson: float = 0.3
    density: float = 7850.0
    friction: float = 0.5
    rolling_friction: float = 0.0
    cor: float = 1.0
    effective_modulus: float | None = None
    kratio: float = 1.0
    beta_n: float = 0.0
    beta_s: float = 0.0
    law: str = "hertz"

    def __post_init__(self) -> None:
        checks = [
            ("young", self.young, self.young > 0, "> 0 Pa"),
            ("poisson", self.poisson, -1.0 < self.poisson < 0.5, "in (-1, 0.5)"),
            ("density", self.density, self.density > 0, "> 0 kg/m^3"),
            ("friction", self.friction, self.friction >= 0, ">= 0"),
            ("rolling_friction", self.rolling_friction, self.rolling_friction >= 0, ">= 0"),
            ("cor", self.cor, 0.0 < self.cor <= 1.0, "in (0, 1]"),
            ("kratio", self.kratio, self.kratio > 0, "> 0"),
            ("beta_n", self.beta_n, 0 <= self.beta_n < 1, "in [0, 1)"),
            ("beta_s", self.beta_s, 0 <= self.beta_s < 1, "in [0, 1)"),
            ("law", self.law, self.law in LAWS, f"one of {sorted(LAWS)}"),
        ]
        for field_name, value, ok, allowed in checks:
            if not ok:
                raise ValueError(f"material '{self.name}': {field_name} = {value!r}: must be "
                                 f"{allowed}")
        if self.effective_modulus is None:
            self.effective_modulus = self.young
        elif not self.effective_modulus > 0:
            raise ValueError(f"material '{self.name}': effective_modulus = "
                             f"{self.effective_modulus!r}: must be > 0 Pa")

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) (Pa)."""
        return self.young / (2.0 * (1.0 + self.poisson))


def hertz_restitution(gamma: float) -> float:
    """Restitution produced by dashpot factor ``gamma`` (``F_d = gamma sqrt(S_n m*) v_n``).

    Solves the non-dimensional impact ``x'' = -x^1.5 - g x^0.25 x'`` with
    ``g = gamma sqrt(3/2)`` (velocity independent for this dashpot) to contact end.
    Used to verify ``hertz_damping_from_cor``.
    """
    from scipy.integrate import solve_ivp

    g = gamma * math.sqrt(1.5)

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        x = max(y[0], 0.0)
        return [y[1], -(x**1.5) - g * x**0.25 * y[1]]

    def end(_t: float, y: np.ndarray) -> float:
        return y[0]

    end.terminal = True
    end.direction = -1
    sol = solve_ivp(rhs, (0.0, 50.0), [1e-12, 1.0], events=end, rtol=1e-11, atol=1e-13,
                    method="DOP853")
    if sol.y_events[0].size == 0:  # over-damped: no rebound within the window
        return 0.0
    return float(-sol.y_events[0][0][1])


def hertz_damping_from_cor(cor: float) -> float:
    """Dashpot factor ``gamma = 2 sqrt(5/6) |ln e| / sqrt(ln^2 e + pi^2)`` (EDEM, Tsuji).

    With ``F_d = gamma sqrt(S_n m*) v_n`` the restitution is velocity independent and
    equals ``e`` (checked against ``hertz_restitution`` to 1e-9 in the tests).
    """
    if cor >= 1.0:
        return 0.0
    lne = math.log(cor)
    return 2.0 * math.sqrt(5.0 / 6.0) * abs(lne) / math.sqrt(lne * lne + math.pi**2)


def pair_table(materials: list[Material]) -> tuple[np.ndarray, np.ndarray]:
    """Pair property table ``[n, n, N_PROPS]`` and per-material linear moduli.

    Mixing: Hertz ``1/E* = sum (1-nu^2)/E``, ``1/G* = sum (2-nu)/G``; friction,
    rolling friction, restitution, kratio and damping ratios: arithmetic mean; the law
    is the first material's when they differ (set explicitly with ``set_pair``).
    """
    n = len(materials)
    tab = np.zeros((n, n, N_PROPS))
    for a, ma in enumerate(materials):
        for b, mb in enumerate(materials):
            set_pair(tab, a, b, ma, mb)
    elin = np.array([m.effective_modulus for m in materials], dtype=np.float64)
    return tab, elin


def set_pair(tab: np.ndarray, a: int, b: int, ma: Material, mb: Material, **override: float
             ) -> None:
    """Fill the (a, b) and (b, a) rows of the pair table from two materials."""
    estar = 1.0 / ((1 - ma.poisson**2) / ma.young + (1 - mb.poisson**2) / mb.young)
    gstar = 1.0 / ((2 - ma.poisson) / ma.shear_modulus + (2 - mb.poisson) / mb.shear_modulus)
    row = np.zeros(N_PROPS)
    row[P_LAW] = LAWS[ma.law]
    row[P_ESTAR] = estar
    row[P_GSTAR] = gstar
    row[P_MU] = 0.5 * (ma.friction + mb.friction)
    row[P_MUR] = 0.5 * (ma.rolling_friction + mb.rolling_friction)
    row[P_GAMMA] = hertz_damping_from_cor(0.5 * (ma.cor + mb.cor))
    row[P_KRATIO] = 0.5 * (ma.kratio + mb.kratio)
    row[P_BETAN] = 0.5 * (ma.beta_n + mb.beta_n)
    row[P_BETAS] = 0.5 * (ma.beta_s + mb.beta_s)
    names = {"law": P_LAW, "friction": P_MU, "rolling_friction": P_MUR, "kratio": P_KRATIO,
             "beta_n": P_BETAN, "beta_s": P_BETAS}
    for k, v in override.items():
        if k == "cor":
            row[P_GAMMA] = hertz_damping_from_cor(float(v))
        elif k == "law":
            row[P_LAW] = LAWS[str(v)]
        else:
            row[names[k]] = float(v)
    tab[a, b] = row
    tab[b, a] = row


@njit(cache=True, inline="always")
def law_normal(law, prop, delta, vn, rstar, mstar, area, lin_k):
    """Normal force magnitude (N, + = repulsive), tangential stiffness (N/m), tangential
    damping coefficient (N s/m), normal stiffness (N/m) and stored energy (J)."""
    if law == HERTZ:
        estar = prop[P_ESTAR]
        sq = np.sqrt(rstar * delta)
        sn = 2.0 * estar * sq
        st = 8.0 * prop[P_GSTAR] * sq
        fe = (4.0 / 3.0) * estar * np.sqrt(rstar) * delta * np.sqrt(delta)
        fn = fe - prop[P_GAMMA] * np.sqrt(sn * mstar) * vn
        ct = prop[P_GAMMA] * np.sqrt(st * mstar)
        energy = 0.4 * fe * delta
        return fn, st, ct, sn, energy
    kn = lin_k
    ks = kn / prop[P_KRATIO]
    fn = kn * delta - 2.0 * prop[P_BETAN] * np.sqrt(mstar * kn) * vn
    ct = 2.0 * prop[P_BETAS] * np.sqrt(mstar * ks)
    return fn, ks, ct, kn, 0.5 * kn * delta * delta


@njit(cache=True, inline="always")
def contact_response(law, prop, n, delta, vrel, wrel, rstar, mstar, istar, area, lin_k, hist,
                     dt, out):
    """Force on the second body and rolling torque on the first, for one contact.

    n: unit normal from body 1 to body 2; vrel: velocity of body 2 minus body 1 at the
    contact point; wrel: omega_1 - omega_2. ``hist`` (shear spring, m) is updated in
    place. Writes out[0:3] force on body 2 (N), out[3:6] rolling torque on body 1
    (N m; body 2 gets minus it), out[6] normal force, out[7] energy, out[8] kn.
    """
    vn = vrel[0] * n[0] + vrel[1] * n[1] + vrel[2] * n[2]
    fn, kt, ct, kn, energy = law_normal(law, prop, delta, vn, rstar, mstar, area, lin_k)
    # shear spring: rotate into the current tangent plane (keep its length), add slip
    hn = hist[0] * n[0] + hist[1] * n[1] + hist[2] * n[2]
    h0 = np.sqrt(hist[0] ** 2 + hist[1] ** 2 + hist[2] ** 2)
    for k in range(3):
        hist[k] -= hn * n[k]
    h1 = np.sqrt(hist[0] ** 2 + hist[1] ** 2 + hist[2] ** 2)
    if h1 > 0.0:
        s = h0 / h1
        for k in range(3):
            hist[k] *= s
    vt = np.empty(3)
    for k in range(3):
        vt[k] = vrel[k] - vn * n[k]
        hist[k] += vt[k] * dt
    ft = np.empty(3)
    for k in range(3):
        ft[k] = -kt * hist[k] - ct * vt[k]
    ftm = np.sqrt(ft[0] ** 2 + ft[1] ** 2 + ft[2] ** 2)
    fmax = prop[P_MU] * (fn if fn > 0.0 else 0.0)
    if ftm > fmax:
        s = fmax / ftm if ftm > 0.0 else 0.0
        for k in range(3):
            ft[k] *= s
            hist[k] = -(ft[k] + ct * vt[k]) / kt if kt > 0.0 else 0.0
    energy += 0.5 * kt * (hist[0] ** 2 + hist[1] ** 2 + hist[2] ** 2)
    for k in range(3):
        out[k] = fn * n[k] + ft[k]
    # rolling resistance (constant directional torque), without reversing the spin
    mur = prop[P_MUR]
    for k in range(3):
        out[3 + k] = 0.0
    if mur > 0.0 and fn > 0.0:
        wn = wrel[0] * n[0] + wrel[1] * n[1] + wrel[2] * n[2]
        wr = np.empty(3)
        for k in range(3):
            wr[k] = wrel[k] - wn * n[k]
        wm = np.sqrt(wr[0] ** 2 + wr[1] ** 2 + wr[2] ** 2)
        if wm > 0.0:
            tq = mur * fn * rstar
            tlim = istar * wm / dt
            if tq > tlim:
                tq = tlim
            for k in range(3):
                out[3 + k] = -tq * wr[k] / wm
    out[6] = fn
    out[7] = energy
    out[8] = kn


@kernel
def pair_forces(pos, vel, omega, radius, mass, inertia, mat, pair_i, pair_j, hist, pairtab,
                elin, length, periodic, dim, thickness, dt, fpair, tpair_i, tpair_j, pinfo):
    """Forces of all listed pairs (prange over pairs; no shared writes).

    fpair[p]: force on j (i gets minus it); tpair_i/tpair_j: torques (N m);
    pinfo[p] = (overlap m, normal force N, energy J, kn N/m).
    """
    m = pair_i.shape[0]
    for p in prange(m):
        i = pair_i[p]
        j = pair_j[p]
        d = np.empty(3)
        d[0] = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
        d[1] = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
        d[2] = min_image(pos[j, 2] - pos[i, 2], length[2], periodic[2])
        dist = np.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
        ri = radius[i]
        rj = radius[j]
        delta = ri + rj - dist
        if delta <= 0.0 or dist == 0.0:
            for k in range(3):
                hist[p, k] = 0.0
                fpair[p, k] = 0.0
                tpair_i[p, k] = 0.0
                tpair_j[p, k] = 0.0
            pinfo[p, 0] = delta
            pinfo[p, 1] = 0.0
            pinfo[p, 2] = 0.0
            pinfo[p, 3] = 0.0
            continue
        n = d / dist
        ai = ri - 0.5 * delta
        aj = rj - 0.5 * delta
        vrel = np.empty(3)
        wrel = np.empty(3)
        # v_c = v + omega x (arm): body i arm +ai n, body j arm -aj n
        wi = omega[i]
        wj = omega[j]
        ci0 = wi[1] * n[2] - wi[2] * n[1]
        ci1 = wi[2] * n[0] - wi[0] * n[2]
        ci2 = wi[0] * n[1] - wi[1] * n[0]
        cj0 = wj[1] * n[2] - wj[2] * n[1]
        cj1 = wj[2] * n[0] - wj[0] * n[2]
        cj2 = wj[0] * n[1] - wj[1] * n[0]
        vrel[0] = (vel[j, 0] - aj * cj0) - (vel[i, 0] + ai * ci0)
        vrel[1] = (vel[j, 1] - aj * cj1) - (vel[i, 1] + ai * ci1)
        vrel[2] = (vel[j, 2] - aj * cj2) - (vel[i, 2] + ai * ci2)
        for k in range(3):
            wrel[k] = wi[k] - wj[k]
        rstar = ri * rj / (ri + rj)
        mstar = mass[i] * mass[j] / (mass[i] + mass[j])
        istar = inertia[i] * inertia[j] / (inertia[i] + inertia[j])
        rmin = ri if ri < rj else rj
        area = 2.0 * rmin * thickness if dim == 2 else np.pi * rmin * rmin
        lin_k = area / (ri / elin[mat[i]] + rj / elin[mat[j]])
        prop = pairtab[mat[i], mat[j]]
        out = np.empty(9)
        contact_response(int(prop[P_LAW]), prop, n, delta, vrel, wrel, rstar, mstar, istar,
                         area, lin_k, hist[p], dt, out)
        f0, f1, f2 = out[0], out[1], out[2]
        fpair[p, 0] = f0
        fpair[p, 1] = f1
        fpair[p, 2] = f2
        # torque = arm x force; body j: (-aj n) x F ; body i: (ai n) x (-F)
        tx = n[1] * f2 - n[2] * f1
        ty = n[2] * f0 - n[0] * f2
        tz = n[0] * f1 - n[1] * f0
        tpair_i[p, 0] = -ai * tx + out[3]
        tpair_i[p, 1] = -ai * ty + out[4]
        tpair_i[p, 2] = -ai * tz + out[5]
        tpair_j[p, 0] = -aj * tx - out[3]
        tpair_j[p, 1] = -aj * ty - out[4]
        tpair_j[p, 2] = -aj * tz - out[5]
        pinfo[p, 0] = delta
        pinfo[p, 1] = out[6]
        pinfo[p, 2] = out[7]
        pinfo[p, 3] = out[8]


@kernel
def gather(start, rev_start, rev_pair, fpair, tpair_i, tpair_j, force, torque):
    """Sum pair forces/torques onto particles (fixed order: deterministic)."""
    n = force.shape[0]
    for i in prange(n):
        fx = 0.0
        fy = 0.0
        fz = 0.0
        tx = 0.0
        ty = 0.0
        tz = 0.0
        for p in range(start[i], start[i + 1]):
            fx -= fpair[p, 0]
            fy -= fpair[p, 1]
            fz -= fpair[p, 2]
            tx += tpair_i[p, 0]
            ty += tpair_i[p, 1]
            tz += tpair_i[p, 2]
        for q in range(rev_start[i], rev_start[i + 1]):
            p = rev_pair[q]
            fx += fpair[p, 0]
            fy += fpair[p, 1]
            fz += fpair[p, 2]
            tx += tpair_j[p, 0]
            ty += tpair_j[p, 1]
            tz += tpair_j[p, 2]
        force[i, 0] = fx
        force[i, 1] = fy
        force[i, 2] = fz
        torque[i, 0] = tx
        torque[i, 1] = ty
        torque[i, 2] = tz

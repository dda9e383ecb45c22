"""One elastic-plastic half-space loaded by surface tractions, increment by increment.

The semi-analytical method of Jacq, Nelias, Lormand and Girodin ("Development of a
three-dimensional semi-analytical elastic-plastic contact code", J. Tribology 2002) as
Gallego, Nelias and Jacq ("A comprehensive method to predict wear and to define the optimum
geometry of fretting surfaces", J. Tribology 2006) use it for fretting: the body is a
half-space z >= 0 whose plastic strain eps_p lives on a volume grid of cuboids; for a
surface traction t = (q_x, q_y, p) (Pa) the total strain is

    eps = grad B[t] + grad M[C : eps_p]                                              (1)

(B: Boussinesq-Cerruti influence of the surface traction, normal *and* tangential; M:
Mindlin's influence of the eigenstress C : eps_p), and eps_p follows the von Mises return
mapping with linear isotropic hardening, flow stress sigma_y + h p (p the cumulated
plastic strain). Each call of :meth:`PlasticHalfSpace.load` applies the increment
t_new - t_old: tamaas's :class:`tamaas.Residual` (Frerot, Bonnet, Anciaux and Molinari, "A
Fourier-accelerated volume integral method for elastoplastic contact", CMAME 2019:
periodic in x and y, FFT along the surface, exact integration in depth) with
:class:`tamaas.materials.IsotropicHardening` solves (1) for the strain increment
(:class:`DFSANECXXSolver`), and the state (strain, plastic strain, p, stress) is committed.
The residual surface displacement, the normal displacement of the plastic strain alone
(Mindlin of C : eps_p at z = 0), is what the contact sees on top of its elastic
deformation (Jacq et al. eq 5: h = h_0 + u_e + u_r).

Everything inside is non-dimensional (length: ``length`` m, stress: E / (1 - nu^2)).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import tamaas as tm
from numpy.typing import NDArray

from tribodem.contact.base import WindowTooSmallError, check_positive
from tribodem.contact.halfspace import model_fields, set_model_fields


class PlasticSolveStopped(WindowTooSmallError):
    """The plastic solve cannot go on (no convergence, or an increase of the equivalent
    plastic strain beyond small strains in one increment). A subclass of the error the
    fretting loop already stops on (the contact leaving the window): the run stops early
    with this message and keeps its outputs (exit 3)."""


def mandel_to_voigt(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """tamaas 2.9 (xx, yy, zz, xy, xz, yz; shear x sqrt 2) -> (xx, yy, zz, yz, xz, xy)."""
    out = np.asarray(a, dtype=float)[..., [0, 1, 2, 5, 4, 3]].copy()
    out[..., 3:] /= math.sqrt(2.0)
    return out


def _overlap(fine: NDArray[np.float64], dx: float, coarse: NDArray[np.float64],
             grid_dx: float) -> NDArray[np.float64]:
    """[n_coarse, n_fine] shares of each fine cell (centres ``fine``, side ``dx``) in each
    coarse cell (centres ``coarse``, side ``grid_dx``): overlap length / ``grid_dx``."""
    lo = np.maximum(fine[None, :] - 0.5 * dx, coarse[:, None] - 0.5 * grid_dx)
    hi = np.minimum(fine[None, :] + 0.5 * dx, coarse[:, None] + 0.5 * grid_dx)
    return np.maximum(hi - lo, 0.0) / grid_dx


def block_average(field: NDArray[np.float64], x0: float, dx: float, grid_x0: float,
                  grid_dx: float, nx: int, y0: float, grid_y0: float, ny: int
                  ) -> NDArray[np.float64]:
    """Cell average of a fine cell field [n, m, ...] (cells of side ``dx``, cell (0, 0)
    centred at (x0, y0), m) on the cells of a coarse grid (side ``grid_dx``, cell (0, 0)
    at (grid_x0, grid_y0), ``nx`` x ``ny``): t_c = sum_f t_f |A_f cap A_c| / |A_c|, the
    overlap areas exact for axis-aligned cells, so the force sum t dA is kept for every
    fine cell inside the coarse grid (those outside are dropped)."""
    f = np.asarray(field, dtype=float)
    n, m = f.shape[:2]
    wx = _overlap(x0 + dx * np.arange(n), dx, grid_x0 + grid_dx * np.arange(nx), grid_dx)
    wy = _overlap(y0 + dx * np.arange(m), dx, grid_y0 + grid_dx * np.arange(ny), grid_dx)
    return np.einsum("in,nm...,jm->ij...", wx, f, wy, optimize=True)


class PlasticHalfSpace:
    """The plastic state of one body: a periodic ``nz x nx x ny`` volume grid under its
    surface (cell centres at x = x0 + i dx, y = y0 + j dx, m; depths z = linspace(0,
    depth, nz), m), bilinear isotropic hardening (``yield_strength`` and ``hardening`` h,
    Pa; ``young`` Pa, ``poisson``), loaded by total surface tractions (Pa) one increment
    at a time (:meth:`load`). ``length`` (m) is the internal length unit (the Hertz radius);
    ``tolerance`` and ``max_iter`` are the nonlinear solver's."""

    def __init__(self, nx: int, ny: int, nz: int, dx: float, depth: float, x0: float,
                 y0: float, young: float, poisson: float, yield_strength: float,
                 hardening: float, length: float, tolerance: float = 1e-6,
                 max_iter: int = 300) -> None:
        for name, v in (("nx", nx), ("ny", ny), ("nz", nz)):
            if int(v) != v or v < 3:
                raise ValueError(f"{name} = {v!r} is not allowed: must be an integer >= 3")
        self.nx, self.ny, self.nz = int(nx), int(ny), int(nz)
        self.dx = check_positive("dx", dx)
        self.depth = check_positive("depth", depth)
        self.length = check_positive("length", length)
        self.x0, self.y0 = float(x0), float(y0)
        self.young = check_positive("young", young)
        self.poisson = float(poisson)
        #: stress unit E / (1 - nu^2), Pa
        self.unit = self.young / (1.0 - self.poisson**2)
        self.yield_strength = check_positive("yield_strength", yield_strength)
        self.hardening = check_positive("hardening", hardening, allow_zero=True)
        self.tolerance = check_positive("tolerance", tolerance)
        self.max_iter = int(max_iter)
        self._build()
        self.reset()

    def _build(self) -> None:
        """Fresh tamaas objects (model, material, residual, solver; the operators' model).
        A :class:`tamaas.Residual` keeps state beyond the model's fields: one rebuilt from
        the fields of a yielded state does not continue it (its residual 20-50 % apart,
        measured), so only an unyielded state is restored exactly."""
        a = self.length
        dims = [self.depth / a, self.nx * self.dx / a, self.ny * self.dx / a]
        shape = [self.nz, self.nx, self.ny]
        self._model = tm.ModelFactory.createModel(tm.model_type.volume_2d, dims, shape)
        self._model.E = self.young / self.unit
        self._model.nu = self.poisson
        self._mat = tm.materials.IsotropicHardening(
            self._model, sigma_y=self.yield_strength / self.unit,
            hardening=self.hardening / self.unit)
        self._res = tm.Residual(self._model, self._mat)
        import tamaas.nonlinear_solvers  # scipy.optimize: imported on first use

        self._nl = tamaas.nonlinear_solvers.DFSANECXXSolver(self._res)
        self._nl.tolerance = self.tolerance
        self._nl.max_iter = self.max_iter
        # a separate model for the operators: applying volume operators on the residual's
        # model corrupts its next solve (measured with EPIC: ratcheting)
        self._aux = tm.ModelFactory.createModel(tm.model_type.volume_2d, dims, shape)
        self._aux.E, self._aux.nu = self._model.E, self._model.nu
        tm.ModelFactory.registerVolumeOperators(self._aux)

    @property
    def x(self) -> NDArray[np.float64]:
        """Cell centres along x, m [nx]."""
        return self.x0 + self.dx * np.arange(self.nx)

    @property
    def y(self) -> NDArray[np.float64]:
        """Cell centres along y, m [ny]."""
        return self.y0 + self.dx * np.arange(self.ny)

    @property
    def z(self) -> NDArray[np.float64]:
        """Depths of the layers, m [nz]."""
        return np.linspace(0.0, self.depth, self.nz)

    def reset(self) -> None:
        """The virgin, unloaded body."""
        for k in list(self._model):
            self._model[k][...] = 0.0
        #: total surface traction now applied (q_x, q_y, p), Pa [nx, ny, 3]
        self.traction = np.zeros((self.nx, self.ny, 3))
        #: residual (plastic) normal surface displacement into the body, m [nx, ny]
        self.residual_displacement = np.zeros((self.nx, self.ny))
        self._residual_stress: NDArray[np.float64] | None = None

    @property
    def cumulated_plastic_strain(self) -> NDArray[np.float64]:
        """Equivalent (cumulated) plastic strain p, - [nz, nx, ny]."""
        return np.array(self._model["cumulated_plastic_strain"], dtype=float)

    @property
    def plastic_strain(self) -> NDArray[np.float64]:
        """Plastic strain tensor, - [nz, nx, ny, 6] (Voigt xx, yy, zz, yz, xz, xy; tensor
        shear components)."""
        return mandel_to_voigt(self._model["plastic_strain"])

    @property
    def stress(self) -> NDArray[np.float64]:
        """Total stress (the applied traction's plus the residual), Pa [nz, nx, ny, 6]
        (Voigt order)."""
        return mandel_to_voigt(self._model["stress"]) * self.unit

    def load(self, traction: NDArray[np.float64]) -> NDArray[np.float64]:
        """Apply the total surface traction ``traction`` (q_x, q_y, p on the body, Pa,
        [nx, ny, 3]; p > 0 compressive) from the one applied now; returns the increment of
        the cumulated plastic strain, - [nz, nx, ny]. Updates the residual surface
        displacement (Mindlin's normal displacement of C : eps_p at z = 0, its mean over
        the grid's border taken as zero: the periodic grid fixes it up to a constant).
        :class:`PlasticSolveStopped` when p would rise by more than :attr:`MAX_INCREMENT`."""
        t = np.asarray(traction, dtype=float)
        if t.shape != (self.nx, self.ny, 3):
            raise ValueError(f"traction of shape {t.shape}: expected ({self.nx}, {self.ny}, 3)")
        inc = t - self.traction
        if not np.any(inc):
            return np.zeros((self.nz, self.nx, self.ny))
        before = self.cumulated_plastic_strain
        self._solve_increment(inc / self.unit, 0)
        dp = np.maximum(self.cumulated_plastic_strain - before, 0.0)
        if dp.max() > self.MAX_INCREMENT:
            raise PlasticSolveStopped(
                f"plastic strain increment {dp.max():.3g} in one traction increment (more than "
                f"{self.MAX_INCREMENT}): outside the small-strain half-space, and the nonlinear "
                "solve is not trustworthy there (a layer's uniform in-plane eigenstrain is "
                "stress-free, so the residual has near-null directions); lower the load or the "
                "friction, or refine the increments")
        self.traction = t.copy()
        self._residual_stress = None
        if dp.max() > 0.0:
            eps_p = np.array(self._model["plastic_strain"], dtype=float)
            eig = np.zeros_like(eps_p)
            self._aux.operators["hooke"](eps_p, eig)
            disp = np.zeros(self._aux.displacement.shape)
            self._aux.operators["mindlin"](eig, disp)
            u = disp[0, ..., 2]
            border = np.concatenate([u[0], u[-1], u[:, 0], u[:, -1]]).mean()
            self.residual_displacement = (u - border) * self.length
        return dp

    #: the largest increment of p one load may give (else :class:`PlasticSolveStopped`)
    MAX_INCREMENT = 0.5
    #: a solve is accepted when its residual is below this share of the initial one
    ACCEPT = 0.05
    #: ... or when its root mean square is below this strain (a yield strain is ~3e-3)
    FLOOR = 1e-7
    #: halvings of a traction increment whose solve is not accepted, at most
    MAX_SPLITS = 4

    def _solve_increment(self, inc: NDArray[np.float64], depth: int) -> None:
        """Solve and commit the (non-dimensional) traction increment ``inc``; a solve whose
        residual norm stays above :attr:`ACCEPT` x the initial one and above an RMS of
        :attr:`FLOOR` (the nonlinear solver stopped at ``max_iter``) is not committed: the
        increment is halved, up to :attr:`MAX_SPLITS` times (then :class:`PlasticSolveStopped`)."""
        self._model.traction[...] = inc
        zero = np.zeros((self.nz, self.nx, self.ny, 6))
        self._res.computeResidual(zero)
        r0 = float(np.linalg.norm(np.asarray(self._res.vector)))
        self._nl.solve()
        x = np.array(self._nl.getStrainIncrement(), dtype=float)
        self._res.computeResidual(x)
        r = float(np.linalg.norm(np.asarray(self._res.vector)))
        self.last_residual = r / r0 if r0 > 0.0 else 0.0
        if r <= max(self.ACCEPT * r0, self.FLOOR * math.sqrt(x.size)):
            self._res.updateState(x)
            return
        if depth >= self.MAX_SPLITS:
            raise PlasticSolveStopped(
                f"plastic solve did not converge (residual {r / r0:.3g} of the initial one "
                f"after {self.MAX_SPLITS} halvings of the traction increment): the traction "
                "is beyond what the half-space's small-strain plasticity carries; lower the "
                "load or the friction, or refine the increments")
        self._solve_increment(0.5 * inc, depth + 1)
        self._solve_increment(0.5 * inc, depth + 1)

    @property
    def residual_stress(self) -> NDArray[np.float64]:
        """Residual stress, Pa [nz, nx, ny, 6] (Voigt): the total stress minus the elastic
        stress of the applied traction (C : grad B[t])."""
        if self._residual_stress is None:
            strain = np.zeros((self.nz, self.nx, self.ny, 6))
            el = np.zeros_like(strain)
            self._aux.operators["boussinesq_gradient"](self.traction / self.unit, strain)
            self._aux.operators["hooke"](strain, el)
            self._residual_stress = self.stress - mandel_to_voigt(el) * self.unit
        return self._residual_stress

    def peak(self) -> tuple[float, float, float]:
        """(max p, its depth m, its x m) of the cumulated plastic strain."""
        p = self.cumulated_plastic_strain
        k = np.unravel_index(int(np.argmax(p)), p.shape)
        return float(p[k]), float(self.z[k[0]]), float(self.x[k[1]])

    def state_dict(self) -> dict[str, Any]:
        """The body's state (tamaas fields, applied traction, residual displacement)."""
        return {"fields": model_fields(self._model), "traction": self.traction.copy(),
                "residual_displacement": self.residual_displacement.copy(),
                "guess": np.array(self._nl.getStrainIncrement(), dtype=float)}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (same grid) into fresh tamaas objects."""
        self._build()
        set_model_fields(self._model, state["fields"])
        # the nonlinear solver starts from its last solution: restored with the state
        np.asarray(self._nl.getStrainIncrement())[...] = state["guess"]
        self.traction = np.array(state["traction"], dtype=float)
        self.residual_displacement = np.array(state["residual_displacement"], dtype=float)
        self._residual_stress = None

"""The exact natural frequencies and mode shapes of a uniform beam of any of three theories.

Every theory's frequencies come from one exact method: at a trial frequency the uniform beam's general
solution is four exponentials e^(s x) whose s^2 solve the dispersion relation
a s^4 + b s^2 + c = 0 (Euler-Bernoulli: EI s^4 - rho A w^2 = 0; Rayleigh adds rho I w^2 s^2; Timoshenko
also the shear flexibility). The boundary conditions at both ends make a 4 x 4 matrix whose determinant
vanishes at a natural frequency. Growing exponentials are written as e^(beta (x - L)), so every entry is
bounded and the determinant keeps its precision at high modes (the cosh(beta L) form loses e^(beta L)
digits). Roots are bracketed on a fine grid of the Euler-Bernoulli frequency parameter and each is
confirmed by the matrix's smallest singular value, which rejects a sign change where the basis switches
(at the Timoshenko cut-off frequency sqrt(kappa G A / rho I)).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ..core.errors import ParameterError

# the boundary conditions of Beam, as (end at x = 0, end at x = L)
_ENDS = {"cantilever": ("clamped", "free"), "simply-supported": ("pinned", "pinned"),
         "clamped-clamped": ("clamped", "clamped"), "free-free": ("free", "free"),
         "clamped-pinned": ("clamped", "pinned")}
# which of (w, psi, M, V) vanish at each kind of end
_ROWS = {"clamped": (0, 1), "pinned": (0, 2), "free": (2, 3)}
LAMBDA_START = 0.3     # below every flexible mode of every bc (EB's lowest is 1.875); rigid-body modes excluded
LAMBDA_STEP = 0.02     # grid of the frequency parameter; roots of these beams are at least 0.3 apart
ROOT_CONFIRM = 1e-7    # smallest / largest singular value at a true root (a spurious sign change is far above)


class _Section:
    """A uniform beam's properties per unit length: EI, rho A, rho I and kappa G A (None: no shear)."""

    def __init__(self, EI, rhoA, rhoI, kGA, L, bc):
        self.EI, self.rhoA, self.rhoI, self.kGA, self.L = EI, rhoA, rhoI, kGA, L
        if bc not in _ENDS:
            raise ParameterError(f"bc={bc!r} must be one of {tuple(_ENDS)}")
        self.bc = bc

    def _w_of(self, lam):
        return (lam / self.L) ** 2 * np.sqrt(self.EI / self.rhoA)

    def _dispersion(self, w):
        """The two roots S = s^2 of a S^2 + b S + c = 0 at circular frequency w."""
        w2 = w * w
        if self.kGA is None:
            a, b, c = self.EI, self.rhoI * w2, -self.rhoA * w2
        else:
            a = self.kGA * self.EI
            b = w2 * (self.kGA * self.rhoI + self.rhoA * self.EI)
            c = self.rhoA * w2 * (self.rhoI * w2 - self.kGA)
        # real roots of opposite sign below the cut-off (c < 0), both negative above it; the stable form
        # q = -(b + sign(b) sqrt(disc)) / 2 keeps the small root's digits
        disc = np.sqrt(max(b * b - 4 * a * c, 0.0))
        q = -(b + (disc if b >= 0 else -disc)) / 2
        return np.array([q / a, c / q if q != 0 else 0.0])

    def _ends(self, s, w):
        """(w, psi, M, V) of the solution e^(s x) with unit amplitude (s may be complex)."""
        if self.kGA is None:
            psi = s
            return np.array([1.0 + 0 * s, psi, self.EI * s * s, self.EI * s ** 3 + self.rhoI * w * w * s])
        psi = (self.kGA * s * s + self.rhoA * w * w) / (self.kGA * s)
        return np.array([1.0 + 0 * s, psi, self.EI * s * psi, self.kGA * (s - psi)])

    def basis(self, w, x):
        """(w, psi, M, V) of the four bounded solutions at positions x: shape (4 quantities, 4 solutions, x)."""
        x = np.asarray(x, float)
        cols, L = [], self.L
        for S in np.real(self._dispersion(w)):
            if S > 0:   # decaying from each end: e^(-beta x) and e^(beta (x - L))
                b = np.sqrt(S)
                cols.append(self._ends(-b, w)[:, None] * np.exp(-b * x))
                cols.append(self._ends(b, w)[:, None] * np.exp(b * (x - L)))
            else:       # oscillating: cos(alpha x) and sin(alpha x) as the real and imaginary parts
                a = np.sqrt(-S) if S < 0 else 1e-12
                v = self._ends(1j * a, w)[:, None] * np.exp(1j * a * x)
                cols += [v.real, v.imag]
        return np.stack(cols, axis=1)

    def matrix(self, w):
        """The 4 x 4 boundary matrix at w, every entry bounded, each row scaled to unit maximum."""
        ends = self.basis(w, [0.0, self.L])
        left, right = _ENDS[self.bc]
        B = np.array([ends[i, :, 0] for i in _ROWS[left]] + [ends[i, :, 1] for i in _ROWS[right]])
        return B / np.max(np.abs(B), axis=1, keepdims=True)

    def fields(self, w, x):
        """Displacement w(x) and section rotation psi(x) of the mode at w (the boundary matrix's null vector),
        scaled so the displacement's largest magnitude over the beam is 1 and positive."""
        c = np.linalg.svd(self.matrix(w))[2][-1]
        grid = np.linspace(0.0, self.L, 801)
        wg = np.einsum("j,jx->x", c, self.basis(w, grid)[0])
        k = int(np.argmax(np.abs(wg)))
        scale = wg[k]
        if 0 < k < grid.size - 1:   # the peak between grid points: the parabola's vertex
            y0, ym, yp = wg[k], wg[k - 1], wg[k + 1]
            curv = yp - 2 * y0 + ym
            if curv != 0:
                scale = y0 - (yp - ym) ** 2 / (8 * curv)
        b = self.basis(w, x)
        return np.einsum("j,jx->x", c, b[0]) / scale, np.einsum("j,jx->x", c, b[1]) / scale

    def omegas(self, n):
        """The first n natural circular frequencies (flexible modes)."""
        def det(lam):
            return float(np.linalg.det(self.matrix(self._w_of(lam))))

        found, lam, d0 = [], LAMBDA_START, det(LAMBDA_START)
        lam_max = (n + 4) * np.pi * 4 + 10     # far beyond the n-th root of every theory
        while len(found) < n and lam < lam_max:
            nxt = lam + LAMBDA_STEP
            d1 = det(nxt)
            if d0 * d1 < 0:
                root = brentq(det, lam, nxt, xtol=1e-13, rtol=1e-15)
                sv = np.linalg.svd(self.matrix(self._w_of(root)), compute_uv=False)
                if sv[-1] <= ROOT_CONFIRM * sv[0]:
                    found.append(self._w_of(root))
            lam, d0 = nxt, d1
        if len(found) < n:
            raise ParameterError(f"only {len(found)} of n={n} modes found below frequency parameter {lam_max:.0f}: "
                                 "ask for fewer modes")
        return np.array(found)



class SectionModes:
    """The modal set a beam class gives ``ModalExpansion``, from its ``_section()`` (cached per mode count)."""

    def _modal_set(self, n):
        sec = self._section()
        cache = self.__dict__.setdefault("_omegas", {})
        if n not in cache:
            cache[n] = sec.omegas(n)
        w = cache[n]

        def fields(r, x):
            return sec.fields(w[r], x)

        mu, rho_i, L = sec.rhoA, sec.rhoI, sec.L

        def rigid(xo, xi):
            if sec.bc != "free-free":
                return []
            t = 1 / np.sqrt(mu * L)                                   # translation, unit modal mass
            r = 1 / np.sqrt(mu * L ** 3 / 12 + rho_i * L)             # rotation about the middle
            return [(t, t), (r * (xo - L / 2), r * (xi - L / 2))]

        return w, fields, mu, rho_i, rigid

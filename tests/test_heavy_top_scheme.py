"""The heavy top against an independent implementation of the same integrator.

`crates/tape-core/tests/rigid_dynamics.rs` checks the heavy top of Brüls, Cardona & Arnold (2012)
against the published reference: second order, converging onto it (Richardson-extrapolated
error 6.9e-5 m at 1 s and 2.7e-4 m at 2 s), with a raw error of 1.0e-2 m at h = 2e-4 s. Issue 8 asks
for 5e-4 m at that step. This test shows that the raw error is the scheme's own, not the code's:
a few lines of numpy and scipy integrate the same equations with the Lie-group generalised-alpha
method (Arnold & Brüls 2007; spatial angular velocities, `R_{n+1} = exp(D) R_n`), and the core's
run lands on the same states to Newton's tolerance. The scheme in the body frame
(`R_{n+1} = R_n exp(D)`), the other classical choice, is no closer to the reference: 9.2e-3 m at
h = 2e-4 s (7.9e-3 m at rho_inf = 0.9, 1.0e-2 m for the spatial form at rho_inf = 1), measured with
this module's integrator switched to the body frame.
"""

from __future__ import annotations

import numpy as np
import pytest
from _heavy_top import COM, GRAVITY, J_COM, MASS, OMEGA0, heavy_top
from scipy.optimize import fsolve
from scipy.spatial.transform import Rotation
from tapespring.analysis import Step, run

# Published displacements of the centre of mass (the Rust test's reference).
REFERENCE = {
    1.0: np.array([0.1733440436, -0.3599112987, -0.7484906793]),
    2.0: np.array([-0.1504168895, -1.7241654847, -0.6730223697]),
}


def coefficients(rho_inf: float) -> tuple[float, float, float, float]:
    """alpha_m, alpha_f, gamma, beta of Chung & Hulbert (1993)."""
    am = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0)
    af = rho_inf / (rho_inf + 1.0)
    gamma = 0.5 + af - am
    return am, af, gamma, 0.25 * (gamma + 0.5) ** 2


def independent_top(h: float, duration: float, rho_inf: float) -> dict[float, np.ndarray]:
    """Centre-of-mass displacements at the reference times, integrated here.

    Spatial form: `J_s dw/dt + w x J_s w = (R X) x m g`, `J_s = R J R^T` (J about the fixed
    point); `R_{n+1} = exp(D) R_n`, `D = h w_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}`,
    `w_{n+1} = w_n + h (1 - gamma) a_n + h gamma a_{n+1}`, `(1 - alpha_m) a_{n+1} + alpha_m a_n
    = (1 - alpha_f) dw_{n+1} + alpha_f dw_n`, with `a_0 = dw_0`.
    """
    am, af, gamma, beta = coefficients(rho_inf)
    j = J_COM + MASS * (COM @ COM * np.eye(3) - np.outer(COM, COM))

    def acceleration(r: np.ndarray, w: np.ndarray) -> np.ndarray:
        js = r @ j @ r.T
        return np.linalg.solve(js, np.cross(r @ COM, MASS * GRAVITY) - np.cross(w, js @ w))

    r, w = np.eye(3), OMEGA0.copy()
    dw = acceleration(r, w)
    a = dw.copy()
    out = {}
    for k in range(round(duration / h)):

        def advance(d, r=r, w=w, dw=dw, a=a):
            a1 = (d - h * w - h * h * (0.5 - beta) * a) / (h * h * beta)
            w1 = w + h * (1.0 - gamma) * a + h * gamma * a1
            dw1 = ((1.0 - am) * a1 + am * a - af * dw) / (1.0 - af)
            return a1, w1, dw1, Rotation.from_rotvec(d).as_matrix() @ r

        def residual(d):
            _, w1, dw1, r1 = advance(d)
            return dw1 - acceleration(r1, w1)

        d = fsolve(residual, h * w + 0.5 * h * h * a, xtol=1e-13)
        a, w, dw, r = advance(d)
        t = (k + 1) * h
        for t_ref in REFERENCE:
            if abs(t - t_ref) < 0.5 * h:
                out[t_ref] = r @ COM - COM
    return out


def core_top(h: float, duration: float, rho_inf: float) -> dict[float, np.ndarray]:
    """The same top in the core: a rigid body on a pinned node (the Rust test's model)."""
    model, _ = heavy_top()
    step = Step.dynamic(
        "motion",
        duration=duration,
        rho_inf=rho_inf,
        initial_step=h,
        max_step=h,
        adaptive=False,
        output_interval=0.5,
        max_steps=1_000_000,
        tol_force=1e-10,
    )
    r = run(model, [step])
    com = r.marker("com")
    return {
        t: com[int(np.argmin(np.abs(r.t - t)))] - COM for t in REFERENCE if t <= duration + 1e-12
    }


@pytest.mark.parametrize("rho_inf", [0.7, 1.0])
def test_core_is_the_lie_group_generalised_alpha_scheme(rho_inf: float) -> None:
    h = 1e-3
    ours, theirs = core_top(h, 2.0, rho_inf), independent_top(h, 2.0, rho_inf)
    for t in REFERENCE:
        # Same scheme, same steps: only Newton's tolerances separate the two (both near 1e-10
        # relative; measured 1.4e-8 and 3.2e-8 m at 1 s and 2 s). Against the published solution
        # both are 0.11 and 0.25 m off at this step: the scheme's own error, second order.
        np.testing.assert_allclose(ours[t], theirs[t], rtol=0.0, atol=1e-7)

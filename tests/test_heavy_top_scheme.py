"""The heavy top against an independent implementation of the same integrator.

`crates/tape-core/tests/validation/rigid_dynamics.rs` checks the heavy top of Brüls, Cardona &
Arnold (2012) against the published reference: second order, converging onto it
(Richardson-extrapolated error 6.9e-5 m at 1 s and 2.7e-4 m at 2 s), with a raw error of 1.0e-2 m at
h = 2e-4 s. Issue 8 asks for 5e-4 m at that step. This test shows that the raw error is the scheme's
own, not the code's: a few lines of numpy and scipy integrate the same equations with the Lie-group
generalised-alpha method (Arnold & Brüls 2007; spatial angular velocities, `R_{n+1} = exp(D) R_n`),
and the core's run lands on the same states to Newton's tolerance. The scheme in the body frame
(`R_{n+1} = R_n exp(D)`), the other classical choice, is no closer to the reference: 9.2e-3 m at h =
2e-4 s (7.9e-3 m at rho_inf = 0.9, 1.0e-2 m for the spatial form at rho_inf = 1), measured with this
module's integrator switched to the body frame.

The 5e-4 m of issue 8 is the bound of a public regression test (Kynema's
`dynamic_heavy_top.cpp`: "maximum observed error is ~2.05e-4") whose model is another one: a
node at the centre of mass, free in translation, and the pin as a spherical joint held by a
Lagrange multiplier (index 3), at rho_inf = 0.9. The same scheme on that model is far closer to
the reference at the same step: 6.7e-4 m at 2 s with h = 2e-4 s (7.1e-4 m at rho_inf = 0.7),
measured with `joint_top` below, and 1.4e-4 m with its angular velocities spatial (`R_{n+1} =
exp(h D) R_n`, the pinned top's form above); 15 times closer than on the pinned body at h = 1e-3
s (tested).
The core has no joints held by multipliers (its ties eliminate unknowns), and issue 8 asks for
the body whose reference node is not its centre of mass, so the core's top is the pinned body.
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


def joint_top(h: float, duration: float, rho_inf: float) -> dict[float, np.ndarray]:
    """Centre-of-mass displacements at the reference times of the top modelled as a body on a
    node at its centre of mass, pinned at the origin by a spherical joint (Kynema's model).

    Unknowns the centre's position `x`, the body's rotation `R` and the joint's force `lam` on
    the body: `m dv/dt = m g + lam`, `J dW/dt + W x J W = p x R^T lam` (body angular velocity `W`,
    `J` about the centre of mass, `p = -COM` the pin from the centre in the body frame),
    `x + R p = 0`; the Lie-group scheme of `independent_top` on R^3 x SO(3) in the body frame
    (`R_{n+1} = R_n exp(h D_W)`), the constraint at index 3 scaled by `1 / (beta h^2)`, and
    accelerations consistent with the joint at t = 0.
    """
    am, af, gamma, beta = coefficients(rho_inf)
    pin = -COM

    def hat(v: np.ndarray) -> np.ndarray:
        return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])

    x, r, w = COM.copy(), np.eye(3), OMEGA0.copy()
    # Accelerations and joint force at t = 0 from the equations and the joint's second derivative.
    lhs = np.zeros((9, 9))
    lhs[0:3, 0:3], lhs[0:3, 6:9] = MASS * np.eye(3), -np.eye(3)
    lhs[3:6, 3:6], lhs[3:6, 6:9] = J_COM, -hat(pin)
    lhs[6:9, 0:3], lhs[6:9, 3:6] = np.eye(3), -hat(pin)
    rhs = np.concatenate([MASS * GRAVITY, -np.cross(w, J_COM @ w), -np.cross(w, np.cross(w, pin))])
    start = np.linalg.solve(lhs, rhs)
    v = np.concatenate([np.cross(w, x), w])
    dv, lam = start[0:6], start[6:9]
    a = dv.copy()
    steps = np.diag(np.concatenate([np.full(6, 1e-3), np.full(3, 1e-4)]))  # accelerations, N
    out = {}
    for k in range(round(duration / h)):

        def advance(z, x=x, r=r, v=v, dv=dv, a=a):
            a1 = z[0:6]
            d = v + (0.5 - beta) * h * a + beta * h * a1
            v1 = v + (1.0 - gamma) * h * a + gamma * h * a1
            dv1 = ((1.0 - am) * a1 + am * a - af * dv) / (1.0 - af)
            return a1, v1, dv1, x + h * d[0:3], r @ Rotation.from_rotvec(h * d[3:6]).as_matrix()

        def residual(z):
            _, v1, dv1, x1, r1 = advance(z)
            lam1, w1 = z[6:9], v1[3:6]
            return np.concatenate(
                [
                    MASS * dv1[0:3] - MASS * GRAVITY - lam1,
                    J_COM @ dv1[3:6] + np.cross(w1, J_COM @ w1) - hat(pin) @ r1.T @ lam1,
                    (x1 + r1 @ pin) / (beta * h * h),
                ]
            )

        # Newton on a central-difference Jacobian (fsolve's progress test stalls at this
        # system's round-off and warns): forces of about 150 N to 1e-8 N, the joint to 1e-14 m.
        z = np.concatenate([a, lam])
        for _ in range(20):
            f = residual(z)
            if np.max(np.abs(f[0:6])) < 1e-8 and np.max(np.abs(f[6:9])) * beta * h * h < 1e-14:
                break
            jac = np.column_stack(
                [(residual(z + e) - residual(z - e)) / (2.0 * e[i]) for i, e in enumerate(steps)]
            )
            z = z - np.linalg.solve(jac, f)
        else:
            raise AssertionError(f"Newton failed at step {k}: residual {np.max(np.abs(f)):.3g}")
        a, v, dv, x, r = advance(z)
        lam = z[6:9]
        t = (k + 1) * h
        for t_ref in REFERENCE:
            if abs(t - t_ref) < 0.5 * h:
                out[t_ref] = x - COM
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


def test_issue_bound_belongs_to_the_joint_model() -> None:
    # The same scheme at the same step on Kynema's model of the top (see the module's docstring)
    # against the core's pinned body: at h = 1e-3 s and 1 s, measured 7.7e-3 m against 0.11 m.
    # A factor of 10 or more says the issue's bound was met on that model by the scheme's own
    # accuracy, where the pinned body's error is the scheme's too (the test above).
    h = 1e-3
    joint_error = np.linalg.norm(joint_top(h, 1.0, 0.7)[1.0] - REFERENCE[1.0])
    core_error = np.linalg.norm(core_top(h, 1.0, 0.7)[1.0] - REFERENCE[1.0])
    assert joint_error < 0.1 * core_error

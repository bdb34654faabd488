//! Geometrically nonlinear 4-node Mindlin-Reissner shell: total-Lagrangian director
//! formulation with MITC4 assumed transverse shear and a Hughes-Brezzi drilling term.
//!
//! Kinematics. Node `a` carries a position `x_a` and an orthonormal triad `Q_a = [t1_a, t2_a, d_a]`
//! whose third column is the director (the reference director is the averaged nodal normal).
//! Bilinear interpolation `x(xi, eta) = N_a x_a`, `d(xi, eta) = N_a d_a`; derivatives with respect
//! to a local orthonormal frame `(e1, e2)` of the reference mid-surface at each Gauss point are
//! written `x_,i`. Strains (Naghdi / Simo-Fox, linear through the thickness):
//!
//! ```text
//! membrane  eps_ij   = (x_,i . x_,j - X_,i . X_,j) / 2                 (Green-Lagrange)
//! bending   kappa_ij = (x_,i . d_,j + x_,j . d_,i - (same)_ref) / 2
//! shear     gamma_i  = x_,i . d - X_,i . D     (MITC4: covariant components tied at the
//!                                               edge mid-points A, B, C, D, Dvorkin & Bathe 1984)
//! drilling  psi_a    = c0 s - s0 c,  c = (t1.x_,1 + t2.x_,2)/2,  s = (t1.x_,2 - t2.x_,1)/2
//! ```
//!
//! `psi_a` measures the drilling rotation of node `a`'s triad relative to the in-plane rotation of
//! the membrane at the element centre (`c0, s0` are the reference values of `c, s`): it vanishes for
//! any rigid motion and any pure stretch, so it does not lock curved shells. Energy per element:
//!
//! ```text
//! Pi = sum_gp w [eps.C_m eps + kappa.C_b kappa]/2 + k_s G t gamma_t.S gamma_t / 2 + k_d (A/4) sum_a psi_a^2 / 2
//! ```
//!
//! The internal force is the gradient of `Pi` with respect to `(u_a, theta_a)` where `theta_a` is the
//! spatial rotation increment (`Q_a <- exp(theta_a^) Q_a`), and the tangent is its exact derivative:
//! material part `B^T C B`, geometric part from the second derivatives of the strains, and for
//! each node the non-symmetric term `-[g_a]x / 2` from the non-commutativity of rotations
//! (`g_a` the rotational internal force).

use nalgebra::{Matrix2, Matrix3, Matrix4, SMatrix, SVector, Vector3, Vector4};

use super::quadrature::{bilinear, GAUSS_2X2};
use crate::error::{Error, Result};
use crate::material::SectionStiffness;
use crate::rotation::{rotated_vector_hessian, skew};

/// Degrees of freedom of one element (4 nodes x 6).
pub const DOFS_PER_ELEMENT: usize = 24;
/// Material strain rows: 6 per Gauss point, 4 MITC4 tying strains, 4 drilling strains.
const N_ROWS: usize = 32;
/// Element vector.
pub type ElementVector = SVector<f64, DOFS_PER_ELEMENT>;
/// Element matrix.
pub type ElementMatrix = SMatrix<f64, DOFS_PER_ELEMENT, DOFS_PER_ELEMENT>;

/// Tying points of the MITC4 shear interpolation: `(xi, eta, direction)` with direction 0 for
/// `gamma_xi` (points B, D) and 1 for `gamma_eta` (points A, C).
const TYING: [(f64, f64, usize); 4] = [(0.0, -1.0, 0), (0.0, 1.0, 0), (-1.0, 0.0, 1), (1.0, 0.0, 1)];

#[derive(Clone, Copy, Debug)]
struct GaussPoint {
    /// Cartesian derivatives of the shape functions `[dN_a/ds1, dN_a/ds2]` [1/m].
    dn: [[f64; 2]; 4],
    /// Integration weight (Jacobian determinant times Gauss weight) [m^2].
    w: f64,
    /// Reference membrane and bending strains (subtracted so the reference state is stress free).
    eps0: [f64; 3],
    kap0: [f64; 3],
}

/// Strains of an element at its Gauss points (for output and strain-rate damping).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShellStrains {
    /// Membrane strains `[e11, e22, 2 e12]` at each Gauss point.
    pub membrane: [[f64; 3]; 4],
    /// Bending strains `[k11, k22, 2 k12]` [1/m] at each Gauss point.
    pub bending: [[f64; 3]; 4],
    /// Covariant transverse shear strains at the tying points B, D, A, C \[m\].
    pub shear: [f64; 4],
    /// Drilling strains at the nodes \[rad\].
    pub drilling: [f64; 4],
}

/// Generalised stress resultants of an element, integrated over their areas: the work conjugates
/// of the strain rows of [`ShellStrains`] (energy = sum of stress times strain / 2).
///
/// Used by the mixed-stress Newton iteration ([`ShellElement::compute_mixed_into`]): the
/// geometric part of the tangent takes these stresses instead of those of the current strains.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ElementStress {
    /// Membrane forces times the Gauss weight, `w C_m eps` [N m], at each Gauss point.
    pub membrane: [[f64; 3]; 4],
    /// Bending moments times the Gauss weight, `w C_b kappa` [N m^2], at each Gauss point.
    pub bending: [[f64; 3]; 4],
    /// Shear forces conjugate to the tying strains, `k_s G t S gamma` [N m].
    pub shear: [f64; 4],
    /// Drilling moments conjugate to the nodal drilling strains, `k_d psi` [N m].
    pub drilling: [f64; 4],
}

/// Nodal rates of an element for Kelvin-Voigt damping: the stresses become
/// `C (strain + eta d(strain)/dt)`, with the strain rates `B v` of the same assumed strains as the
/// elastic ones (so a rigid motion has none).
#[derive(Clone, Copy, Debug, Default)]
pub struct Viscous {
    /// Nodal velocities [m/s].
    pub v: [Vector3<f64>; 4],
    /// Nodal angular velocities, spatial [rad/s].
    pub w: [Vector3<f64>; 4],
    /// Viscosity eta \[s\].
    pub eta: f64,
    /// `d(velocity)/d(displacement)` of the time integrator [1/s]: the damping matrix
    /// `eta K_material` enters the tangent times this factor.
    pub gamma_prime: f64,
    /// Per node, what the velocities' Jacobian with respect to the node's spatial rotation
    /// increment `theta_a` adds to `gamma'`: `[d v_a / d theta_a, d w_a / d theta_a - gamma' I]`
    /// [m/s, 1/s] (zero: `v_a` does not depend on `theta_a` and `d w_a = gamma' d theta_a`).
    /// A time integrator on the rotation vector `D` of the step has `d w = gamma' T^-T(D) d theta`,
    /// and a node tied at lever `l` to a moving node has `v = v_r + w_r x l` (see
    /// [`crate::assembly::System::rates`]).
    pub rotation_jacobian: [[Matrix3<f64>; 2]; 4],
    /// The consistent tangent: `eta B^T C d(B v)/dq` and the rotation Jacobians, and in the
    /// mixed iteration the viscous stresses in the geometric part (false: neither, the tangent
    /// of the strain rates at fixed `B`; Newton converges linearly at a rate ~ `eta |grad v|`).
    pub consistent: bool,
}

impl Viscous {
    fn velocity(&self) -> [f64; DOFS_PER_ELEMENT] {
        let mut out = [0.0; DOFS_PER_ELEMENT];
        for a in 0..4 {
            out[6 * a..6 * a + 3].copy_from_slice(self.v[a].as_slice());
            out[6 * a + 3..6 * a + 6].copy_from_slice(self.w[a].as_slice());
        }
        out
    }
}

/// Generalised strains of an element (membrane and bending at the 2 x 2 Gauss points, the four
/// tying shear strains, the four nodal drilling strains).
pub const N_STRAINS: usize = 32;

/// An element's generalised strains and the viscous stresses conjugate to them (times the
/// quadrature weights, so that their product is a work \[J\]), recorded by the Kelvin-Voigt kernel
/// for an energy balance consistent with the strain energy: see [`ViscousWork::work_to`].
#[derive(Clone, Copy, Debug)]
pub struct ViscousWork {
    /// Generalised strains, relative to the reference configuration \[-, 1/m, -, -\].
    pub strain: [f64; N_STRAINS],
    /// Viscous stresses `eta C d(strain)/dt` conjugate to them, times the weights [N m, N m, N m,
    /// N m].
    pub stress: [f64; N_STRAINS],
}

impl Default for ViscousWork {
    fn default() -> Self {
        Self {
            strain: [0.0; N_STRAINS],
            stress: [0.0; N_STRAINS],
        }
    }
}

impl ViscousWork {
    /// Work of the viscous stresses from this state to `next` \[J\]: the trapezoidal rule on the
    /// stresses times the strain increments. It is the quadrature under which the strain energy's
    /// change `1/2 (s_0 + s_1) . (e_1 - e_0)` is exact, and the one a time integrator's forces do
    /// on its increments; the trapezoidal rule on the dissipated power instead over-counts a
    /// step's dissipation by `h / 4 (p_1 - p_0) . (r_1 - r_0) > 0` for rates `r` that change
    /// within the step (the stiff, overdamped modes a sudden release excites), so the numerical
    /// remainder of the balance came out negative.
    #[must_use]
    pub fn work_to(&self, next: &Self) -> f64 {
        (0..N_STRAINS)
            .map(|i| 0.5 * (self.stress[i] + next.stress[i]) * (next.strain[i] - self.strain[i]))
            .sum()
    }
}

/// `rows[i] . b` for each of the `R` rows, each sum exactly [`dot24`]'s (in index order from
/// -0.0), the rows' sums interleaved so that their chains of dependent additions overlap instead
/// of running one after the other.
#[inline]
fn dots24<const R: usize>(rows: &[[f64; DOFS_PER_ELEMENT]], b: &[f64; DOFS_PER_ELEMENT]) -> [f64; R] {
    let mut acc = [-0.0; R];
    for (k, bk) in b.iter().enumerate() {
        for (a, row) in acc.iter_mut().zip(rows) {
            *a += row[k] * bk;
        }
    }
    acc
}

#[inline]
fn dot24(a: &[f64; DOFS_PER_ELEMENT], b: &[f64; DOFS_PER_ELEMENT]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// A 4-node shell element with its reference geometry precomputed.
#[derive(Clone, Debug)]
pub struct ShellElement {
    /// Global indices of the element's nodes.
    pub nodes: [usize; 4],
    gp: [GaussPoint; 4],
    /// Shape-function coefficients of the tying points: `x_t = sum_a cg[t][a] x_a` (covariant base
    /// vector) and `d_t = sum_a cd[t][a] d_a`.
    cg: [[f64; 4]; 4],
    cd: [[f64; 4]; 4],
    gamma0: [f64; 4],
    /// `S_tt' = sum_gp w sum_i beta_it beta_it'`, the shear energy metric on tying strains [m^2 / m^2].
    shear_metric: Matrix4<f64>,
    /// `L^T` with `shear_metric = L L^T`.
    shear_factor: Matrix4<f64>,
    dn_centre: [[f64; 2]; 4],
    drill_ref: [(f64, f64); 4],
    psi0: [f64; 4],
    area: f64,
}

#[inline]
fn columns(q: &Matrix3<f64>) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    (
        q.column(0).into_owned(),
        q.column(1).into_owned(),
        q.column(2).into_owned(),
    )
}

/// Local orthonormal frame of the reference surface at `(xi, eta)`, the Cartesian shape-function
/// derivatives there, and the Jacobian determinant; `None` if the map is degenerate.
fn cartesian(x: &[Vector3<f64>; 4], xi: f64, eta: f64) -> Option<([[f64; 2]; 4], f64, Matrix2<f64>)> {
    let (_, dn) = bilinear(xi, eta);
    let mut g = [Vector3::zeros(); 2];
    for a in 0..4 {
        g[0] += dn[a][0] * x[a];
        g[1] += dn[a][1] * x[a];
    }
    let n = g[0].cross(&g[1]);
    if n.norm() <= 1e-14 * g[0].norm_squared().max(g[1].norm_squared()) {
        return None;
    }
    let e3 = n.normalize();
    let e1 = g[0].normalize();
    let e2 = e3.cross(&e1);
    let jac = Matrix2::new(g[0].dot(&e1), g[0].dot(&e2), g[1].dot(&e1), g[1].dot(&e2));
    let det = jac.determinant();
    let inv = jac.try_inverse()?;
    let mut dns = [[0.0; 2]; 4];
    for a in 0..4 {
        for i in 0..2 {
            dns[a][i] = inv[(i, 0)] * dn[a][0] + inv[(i, 1)] * dn[a][1];
        }
    }
    (det > 0.0).then_some((dns, det, inv))
}

impl ShellElement {
    /// Precomputes the reference geometry from the nodal reference positions `x` \[m\] and the
    /// reference nodal triads `q` (columns `t1, t2, D`).
    ///
    /// # Errors
    /// [`Error::InvalidMesh`] if the element is degenerate or its normal opposes a nodal director.
    pub fn try_new(nodes: [usize; 4], x: &[Vector3<f64>; 4], q: &[Matrix3<f64>; 4]) -> Result<Self> {
        let degenerate = || Error::InvalidMesh(format!("element with nodes {nodes:?} is degenerate or inverted"));
        let mut gp = [GaussPoint {
            dn: [[0.0; 2]; 4],
            w: 0.0,
            eps0: [0.0; 3],
            kap0: [0.0; 3],
        }; 4];
        let mut beta = [[[0.0; 4]; 2]; 4];
        for (p, &(xi, eta)) in GAUSS_2X2.iter().enumerate() {
            let (dn, det, inv) = cartesian(x, xi, eta).ok_or_else(degenerate)?;
            gp[p].dn = dn;
            gp[p].w = det;
            // gamma_i = sum_alpha inv[i][alpha] gamma_alpha, gamma_xi = (1-eta)/2 g_B + (1+eta)/2 g_D, ...
            let interp = [0.5 * (1.0 - eta), 0.5 * (1.0 + eta), 0.5 * (1.0 - xi), 0.5 * (1.0 + xi)];
            for i in 0..2 {
                for (t, &(_, _, dir)) in TYING.iter().enumerate() {
                    beta[p][i][t] = inv[(i, dir)] * interp[t];
                }
            }
        }
        let (dn_centre, _, _) = cartesian(x, 0.0, 0.0).ok_or_else(degenerate)?;
        let mut cg = [[0.0; 4]; 4];
        let mut cd = [[0.0; 4]; 4];
        for (t, &(xi, eta, dir)) in TYING.iter().enumerate() {
            let (n, dn) = bilinear(xi, eta);
            for a in 0..4 {
                cg[t][a] = dn[a][dir];
                cd[t][a] = n[a];
            }
        }
        let mut shear_metric = Matrix4::zeros();
        for p in 0..4 {
            for i in 0..2 {
                let b = Vector4::from(beta[p][i]);
                shear_metric += b * b.transpose() * gp[p].w;
            }
        }
        let area = gp.iter().map(|g| g.w).sum();
        // Reference directors must agree with the element normal (consistent orientation).
        let diagonal_normal = (x[2] - x[0]).cross(&(x[3] - x[1]));
        let normal_ok = q.iter().all(|qa| qa.column(2).dot(&diagonal_normal) > 0.0);
        if !normal_ok {
            return Err(Error::InvalidMesh(format!(
                "element with nodes {nodes:?} is oriented against its nodal normals (inconsistent orientation of neighbouring elements)"
            )));
        }
        let mut drill_ref = [(0.0, 0.0); 4];
        let xc = centre_gradient(&dn_centre, x);
        for a in 0..4 {
            let (t1, t2, _) = columns(&q[a]);
            drill_ref[a] = (
                0.5 * (t1.dot(&xc[0]) + t2.dot(&xc[1])),
                0.5 * (t1.dot(&xc[1]) - t2.dot(&xc[0])),
            );
        }
        let mut element = Self {
            nodes,
            gp,
            cg,
            cd,
            gamma0: [0.0; 4],
            shear_metric,
            shear_factor: shear_metric
                .cholesky()
                .ok_or_else(degenerate)?
                .l()
                .transpose(),
            dn_centre,
            drill_ref,
            psi0: [0.0; 4],
            area,
        };
        let s = element.strains(x, q);
        for p in 0..4 {
            element.gp[p].eps0 = s.membrane[p];
            element.gp[p].kap0 = s.bending[p];
        }
        element.gamma0 = s.shear;
        element.psi0 = s.drilling;
        Ok(element)
    }

    /// Reference area of the element [m^2].
    #[must_use]
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Consistent nodal areas `int N_a dA` over the reference surface [m^2] (2 x 2 Gauss rule):
    /// the nodal weights of a uniform load per unit area; they sum to the area.
    #[must_use]
    pub fn nodal_areas(&self) -> [f64; 4] {
        let mut w = [0.0; 4];
        for (gp, &(xi, eta)) in self.gp.iter().zip(&GAUSS_2X2) {
            let (n, _) = bilinear(xi, eta);
            for a in 0..4 {
                w[a] += n[a] * gp.w;
            }
        }
        w
    }

    /// Strains in the configuration `(x, q)` (zero in the reference configuration).
    #[must_use]
    pub fn strains(&self, x: &[Vector3<f64>; 4], q: &[Matrix3<f64>; 4]) -> ShellStrains {
        let d = q.map(|qa| qa.column(2).into_owned());
        let mut s = ShellStrains::default();
        for (p, g) in self.gp.iter().enumerate() {
            let (xs, ds) = gradients(&g.dn, x, &d);
            s.membrane[p] = [
                0.5 * xs[0].norm_squared() - g.eps0[0],
                0.5 * xs[1].norm_squared() - g.eps0[1],
                xs[0].dot(&xs[1]) - g.eps0[2],
            ];
            s.bending[p] = [
                xs[0].dot(&ds[0]) - g.kap0[0],
                xs[1].dot(&ds[1]) - g.kap0[1],
                xs[0].dot(&ds[1]) + xs[1].dot(&ds[0]) - g.kap0[2],
            ];
        }
        for t in 0..4 {
            let (gt, dt) = self.tying_vectors(t, x, &d);
            s.shear[t] = gt.dot(&dt) - self.gamma0[t];
        }
        let xc = centre_gradient(&self.dn_centre, x);
        for a in 0..4 {
            let (t1, t2, _) = columns(&q[a]);
            let (u, v) = self.drill_vectors(a, &xc);
            s.drilling[a] = 0.5 * (t1.dot(&u) - t2.dot(&v)) - self.psi0[a];
        }
        s
    }

    #[inline]
    fn tying_vectors(&self, t: usize, x: &[Vector3<f64>; 4], d: &[Vector3<f64>; 4]) -> (Vector3<f64>, Vector3<f64>) {
        let mut gt = Vector3::zeros();
        let mut dt = Vector3::zeros();
        for a in 0..4 {
            gt += self.cg[t][a] * x[a];
            dt += self.cd[t][a] * d[a];
        }
        (gt, dt)
    }

    /// Adds the force gradients (with respect to `x_a` and `d_a`) of the tying-strain shear forces
    /// `qv`, given the tying vectors `gt`, `dt`.
    #[inline]
    fn add_shear_forces(
        &self,
        qv: &Vector4<f64>,
        gt: &[Vector3<f64>; 4],
        dt: &[Vector3<f64>; 4],
        f_x: &mut [Vector3<f64>; 4],
        f_d: &mut [Vector3<f64>; 4],
    ) {
        for t in 0..4 {
            for a in 0..4 {
                f_x[a] += qv[t] * self.cg[t][a] * dt[t];
                f_d[a] += qv[t] * self.cd[t][a] * gt[t];
            }
        }
    }

    #[inline]
    fn drill_vectors(&self, a: usize, xc: &[Vector3<f64>; 2]) -> (Vector3<f64>, Vector3<f64>) {
        let (c0, s0) = self.drill_ref[a];
        (c0 * xc[1] - s0 * xc[0], c0 * xc[0] + s0 * xc[1])
    }

    /// Strain energy \[J\] in the configuration `(x, q)`.
    #[must_use]
    pub fn energy(&self, x: &[Vector3<f64>; 4], q: &[Matrix3<f64>; 4], sec: &SectionStiffness) -> f64 {
        let s = self.strains(x, q);
        let mut e = 0.0;
        for (p, g) in self.gp.iter().enumerate() {
            let eps = Vector3::from(s.membrane[p]);
            let kap = Vector3::from(s.bending[p]);
            e += 0.5 * g.w * (eps.dot(&(sec.membrane * eps)) + kap.dot(&(sec.bending * kap)));
        }
        let gam = Vector4::from(s.shear);
        e += 0.5 * sec.shear * gam.dot(&(self.shear_metric * gam));
        let kd = sec.drilling * self.area * 0.25;
        e + 0.5 * kd * s.drilling.iter().map(|p| p * p).sum::<f64>()
    }

    /// Stresses `C (eps + B delta)` of the strains linearised at `(x, q)` in the direction of the
    /// nodal increments `dx` \[m\] and spatial rotation increments `dtheta` \[rad\] (zero increments give
    /// the stresses of the configuration). This is the stress update of the mixed Newton iteration:
    /// the stresses follow the linearised kinematics, so the large spurious membrane stresses that
    /// a displacement predictor or correction produces in a thin shell do not enter the next
    /// tangent (Magisano, Leonetti & Garcea 2017, CMAME 313:986).
    #[must_use]
    pub fn linearised_stress(
        &self,
        x: &[Vector3<f64>; 4],
        q: &[Matrix3<f64>; 4],
        sec: &SectionStiffness,
        dx: &[Vector3<f64>; 4],
        dtheta: &[Vector3<f64>; 4],
    ) -> ElementStress {
        let (mut t1, mut t2, mut d) = ([Vector3::zeros(); 4], [Vector3::zeros(); 4], [Vector3::zeros(); 4]);
        for a in 0..4 {
            (t1[a], t2[a], d[a]) = columns(&q[a]);
        }
        let dd: [Vector3<f64>; 4] = std::array::from_fn(|a| dtheta[a].cross(&d[a]));
        // Strains of the configuration plus their directional derivatives.
        let s = self.strains(x, q);
        let mut out = ElementStress::default();
        for (p, g) in self.gp.iter().enumerate() {
            let (xs, ds) = gradients(&g.dn, x, &d);
            let (dxs, dds) = gradients(&g.dn, dx, &dd);
            let eps = Vector3::from(s.membrane[p])
                + Vector3::new(
                    xs[0].dot(&dxs[0]),
                    xs[1].dot(&dxs[1]),
                    xs[0].dot(&dxs[1]) + dxs[0].dot(&xs[1]),
                );
            let kap = Vector3::from(s.bending[p])
                + Vector3::new(
                    dxs[0].dot(&ds[0]) + xs[0].dot(&dds[0]),
                    dxs[1].dot(&ds[1]) + xs[1].dot(&dds[1]),
                    dxs[0].dot(&ds[1]) + xs[0].dot(&dds[1]) + dxs[1].dot(&ds[0]) + xs[1].dot(&dds[0]),
                );
            out.membrane[p] = (sec.membrane * eps * g.w).into();
            out.bending[p] = (sec.bending * kap * g.w).into();
        }
        let mut gam = Vector4::from(s.shear);
        for t in 0..4 {
            let (gt, dt) = self.tying_vectors(t, x, &d);
            let (dgt, ddt) = self.tying_vectors(t, dx, &dd);
            gam[t] += dgt.dot(&dt) + gt.dot(&ddt);
        }
        out.shear = (self.shear_metric * gam * sec.shear).into();
        let xc = centre_gradient(&self.dn_centre, x);
        let dxc = centre_gradient(&self.dn_centre, dx);
        let kd = sec.drilling * self.area * 0.25;
        for a in 0..4 {
            let (u, v) = self.drill_vectors(a, &xc);
            let (du, dv) = self.drill_vectors(a, &dxc);
            let (dt1, dt2) = (dtheta[a].cross(&t1[a]), dtheta[a].cross(&t2[a]));
            let dpsi = 0.5 * (dt1.dot(&u) + t1[a].dot(&du) - dt2.dot(&v) - t2[a].dot(&dv));
            out.drilling[a] = kd * (s.drilling[a] + dpsi);
        }
        out
    }

    /// Internal force `f` (gradient of the strain energy) and, if `k` is given, the consistent
    /// tangent, in the configuration `(x, q)`; returns the strain energy \[J\].
    ///
    /// Layout of `f` and `k`: node-major, `[u_x, u_y, u_z, theta_x, theta_y, theta_z]` per node.
    pub fn compute_into(
        &self,
        x: &[Vector3<f64>; 4],
        q: &[Matrix3<f64>; 4],
        sec: &SectionStiffness,
        f: &mut ElementVector,
        k: Option<&mut ElementMatrix>,
    ) -> f64 {
        self.compute_mixed_into(x, q, sec, None, f, k, None)
    }

    /// As [`Self::compute_into`], with the geometric part of the tangent (every term in which the
    /// stresses multiply second derivatives of the strains, including the rotational `-[g]x / 2`)
    /// taken from `stress` when it is given: the tangent of the mixed (Hellinger-Reissner) Newton
    /// iteration, whose stresses are extrapolated linearly from the previous iterate (see
    /// [`Self::linearised_stress`]). `f` is always the true internal force. If `f_geo` is given it
    /// receives the force of the geometric stresses (`B^T stress`; `f` when `stress` is `None`).
    #[allow(clippy::too_many_arguments)]
    pub fn compute_mixed_into(
        &self,
        x: &[Vector3<f64>; 4],
        q: &[Matrix3<f64>; 4],
        sec: &SectionStiffness,
        stress: Option<&ElementStress>,
        f: &mut ElementVector,
        k: Option<&mut ElementMatrix>,
        f_geo: Option<&mut ElementVector>,
    ) -> f64 {
        self.kernel(x, q, sec, stress, None, f, k, f_geo, None).0
    }

    /// Internal force of the Kelvin-Voigt material, elastic plus viscous stresses
    /// `C (eps + eta B v)`, and, if `k` is given, its tangent for a time integrator whose
    /// velocities move by `gamma'` times the increments; with `viscous.consistent` the exact one
    /// (the velocities' rotation Jacobians `viscous.rotation_jacobian` included):
    ///
    /// ```text
    /// k = (1 + eta gamma') B^T C B  +  eta B^T C d(B v)/dq  +  geometric part of C (eps + eta B v)
    /// ```
    ///
    /// (stiffness plus damping matrix; the derivative of the strain rates in the configuration at
    /// fixed nodal velocities and angular velocities, not symmetric, of relative order
    /// `eta |grad v|`; the geometric part of the total stresses). Returns the strain energy \[J\]
    /// and the dissipated power `eta rate . C rate` \[W\]. Without `viscous.consistent` the middle
    /// term is left out (linear convergence at a rate of order `eta |grad v|`). `work`, if given,
    /// receives the strains and viscous stresses (see [`ViscousWork`]).
    #[allow(clippy::too_many_arguments)]
    pub fn compute_viscous_into(
        &self,
        x: &[Vector3<f64>; 4],
        q: &[Matrix3<f64>; 4],
        sec: &SectionStiffness,
        viscous: &Viscous,
        f: &mut ElementVector,
        k: Option<&mut ElementMatrix>,
        work: Option<&mut ViscousWork>,
    ) -> (f64, f64) {
        self.kernel(x, q, sec, None, Some(viscous), f, k, None, work)
    }

    /// As [`Self::compute_viscous_into`], with the geometric part of the tangent from the elastic
    /// `stress` of the mixed iteration (see [`Self::compute_mixed_into`]), plus, with
    /// `viscous.consistent`, the current viscous stresses (which follow the velocities, not the
    /// linearised kinematics: with them the tangent is the consistent one once `stress` has
    /// converged). `f_geo` receives the force of the geometric stresses.
    #[allow(clippy::too_many_arguments)]
    pub fn compute_viscous_mixed_into(
        &self,
        x: &[Vector3<f64>; 4],
        q: &[Matrix3<f64>; 4],
        sec: &SectionStiffness,
        viscous: &Viscous,
        stress: &ElementStress,
        f: &mut ElementVector,
        k: &mut ElementMatrix,
        f_geo: &mut ElementVector,
        work: Option<&mut ViscousWork>,
    ) -> (f64, f64) {
        self.kernel(x, q, sec, Some(stress), Some(viscous), f, Some(k), Some(f_geo), work)
    }

    #[allow(clippy::too_many_lines, clippy::too_many_arguments)]
    fn kernel(
        &self,
        x: &[Vector3<f64>; 4],
        q: &[Matrix3<f64>; 4],
        sec: &SectionStiffness,
        stress: Option<&ElementStress>,
        viscous: Option<&Viscous>,
        f: &mut ElementVector,
        k: Option<&mut ElementMatrix>,
        f_geo: Option<&mut ElementVector>,
        mut work: Option<&mut ViscousWork>,
    ) -> (f64, f64) {
        let vel = viscous.map(Viscous::velocity);
        let eta = viscous.map_or(0.0, |v| v.eta);
        let mut power = 0.0;
        let (mut t1, mut t2, mut d) = ([Vector3::zeros(); 4], [Vector3::zeros(); 4], [Vector3::zeros(); 4]);
        for a in 0..4 {
            (t1[a], t2[a], d[a]) = columns(&q[a]);
        }
        // Energy gradients with respect to x_a and to the rotated vectors d_a, t1_a, t2_a.
        let mut f_x = [Vector3::zeros(); 4];
        let mut f_d = [Vector3::zeros(); 4];
        let mut f_t1 = [Vector3::zeros(); 4];
        let mut f_t2 = [Vector3::zeros(); 4];
        // Second-derivative coefficients: x_a.x_b, x_a.d_b, x_a.t1_b, x_a.t2_b.
        let mut sxx = [[0.0; 4]; 4];
        let mut sxd = [[0.0; 4]; 4];
        let mut sxt1 = [[0.0; 4]; 4];
        let mut sxt2 = [[0.0; 4]; 4];
        let tangent = k.is_some();
        // Geometric stresses of the mixed iteration, and the force gradients they give.
        let mixed = stress.filter(|_| tangent || f_geo.is_some());
        let mut gf_x = [Vector3::zeros(); 4];
        let mut gf_d = [Vector3::zeros(); 4];
        let mut gf_t1 = [Vector3::zeros(); 4];
        let mut gf_t2 = [Vector3::zeros(); 4];
        // Material rows of all integration points, column-major by DOF: sqrt(w) L^T B. Only with
        // a tangent: zeroing the 6 kB would cost a residual-only call a fifth of its time.
        // (`then`, not `then_some`: the zeroing must not happen without a tangent.)
        #[allow(clippy::unnecessary_lazy_evaluations)]
        let mut btil_rows = tangent.then(|| [0.0; DOFS_PER_ELEMENT * N_ROWS]);
        let mut n_rows = 0;
        // With viscous stresses and a tangent, the same rows of `d(B v)/dq` at fixed nodal
        // velocities (the strain rates' own configuration derivative), for `B^T C eta d(B v)/dq`.
        let consistent = viscous.is_some_and(|v| v.consistent);
        #[allow(clippy::unnecessary_lazy_evaluations)]
        let mut bdot_rows = (tangent && eta > 0.0 && consistent).then(|| [0.0; DOFS_PER_ELEMENT * N_ROWS]);
        let (vv, ww) = viscous.map_or(([Vector3::zeros(); 4], [Vector3::zeros(); 4]), |v| (v.v, v.w));
        // Director rates `w_a x d_a`.
        let dd: [Vector3<f64>; 4] = std::array::from_fn(|a| ww[a].cross(&d[a]));
        let mut energy = 0.0;

        // Membrane and bending at the 2x2 Gauss points.
        for (gp_index, g) in self.gp.iter().enumerate() {
            let (xs, ds) = gradients(&g.dn, x, &d);
            let eps = Vector3::new(
                0.5 * xs[0].norm_squared() - g.eps0[0],
                0.5 * xs[1].norm_squared() - g.eps0[1],
                xs[0].dot(&xs[1]) - g.eps0[2],
            );
            let kap = Vector3::new(
                xs[0].dot(&ds[0]) - g.kap0[0],
                xs[1].dot(&ds[1]) - g.kap0[1],
                xs[0].dot(&ds[1]) + xs[1].dot(&ds[0]) - g.kap0[2],
            );
            let mut n = sec.membrane * eps * g.w;
            let mut m = sec.bending * kap * g.w;
            energy += 0.5 * (n.dot(&eps) + m.dot(&kap));
            let rows = (tangent || vel.is_some()).then(|| gauss_rows(&g.dn, &xs, &ds, &d));
            let (mut nv, mut mv) = (Vector3::zeros(), Vector3::zeros());
            if let (Some(vel), Some(rows)) = (&vel, &rows) {
                let r: [f64; 6] = dots24(rows, vel);
                let (de, dk) = (Vector3::new(r[0], r[1], r[2]), Vector3::new(r[3], r[4], r[5]));
                (nv, mv) = (sec.membrane * de * (eta * g.w), sec.bending * dk * (eta * g.w));
                power += nv.dot(&de) + mv.dot(&dk);
                n += nv;
                m += mv;
            }
            if let Some(w) = work.as_deref_mut() {
                let i = 6 * gp_index;
                w.strain[i..i + 3].copy_from_slice(eps.as_slice());
                w.strain[i + 3..i + 6].copy_from_slice(kap.as_slice());
                w.stress[i..i + 3].copy_from_slice(nv.as_slice());
                w.stress[i + 3..i + 6].copy_from_slice(mv.as_slice());
            }
            add_gauss_forces(&g.dn, &xs, &ds, &n, &m, &mut f_x, &mut f_d);
            let (n, m) = match mixed {
                Some(st) => {
                    let (mut n, mut m) = (
                        Vector3::from(st.membrane[gp_index]),
                        Vector3::from(st.bending[gp_index]),
                    );
                    // The viscous stresses are the current ones (they follow the velocities).
                    if consistent {
                        n += nv;
                        m += mv;
                    }
                    add_gauss_forces(&g.dn, &xs, &ds, &n, &m, &mut gf_x, &mut gf_d);
                    (n, m)
                }
                None => (n, m),
            };
            if let (Some(btil), Some(rows)) = (btil_rows.as_mut(), &rows) {
                // Rows of B premultiplied by sqrt(w) L^T.
                let sw = g.w.sqrt();
                put_rows(btil, n_rows, &sec.membrane_factor, &rows[..3], sw);
                put_rows(btil, n_rows + 3, &sec.bending_factor, &rows[3..], sw);
                if let Some(bdot) = bdot_rows.as_mut() {
                    let (vs, dds) = gradients(&g.dn, &vv, &dd);
                    let rrows = gauss_rate_rows(&g.dn, &xs, &vs, &dds, &d, &ww);
                    put_rows(bdot, n_rows, &sec.membrane_factor, &rrows[..3], sw);
                    put_rows(bdot, n_rows + 3, &sec.bending_factor, &rrows[3..], sw);
                }
                n_rows += 6;
                for a in 0..4 {
                    let [pa, ra] = g.dn[a];
                    for bb in 0..4 {
                        let [pb, rb] = g.dn[bb];
                        let cross = pa * rb + ra * pb;
                        sxx[a][bb] += n[0] * pa * pb + n[1] * ra * rb + n[2] * cross;
                        sxd[a][bb] += m[0] * pa * pb + m[1] * ra * rb + m[2] * cross;
                    }
                }
            }
        }

        // Transverse shear (MITC4 tying strains).
        let mut gt = [Vector3::zeros(); 4];
        let mut dt = [Vector3::zeros(); 4];
        let mut gam = Vector4::zeros();
        for t in 0..4 {
            (gt[t], dt[t]) = self.tying_vectors(t, x, &d);
            gam[t] = gt[t].dot(&dt[t]) - self.gamma0[t];
        }
        let mut qv = self.shear_metric * gam * sec.shear;
        energy += 0.5 * gam.dot(&qv);
        let shear_rows = (tangent || vel.is_some()).then(|| {
            let mut rows = [[0.0; DOFS_PER_ELEMENT]; 4];
            for t in 0..4 {
                for a in 0..4 {
                    let c = 6 * a;
                    rows[t][c..c + 3].copy_from_slice((self.cg[t][a] * dt[t]).as_slice());
                    rows[t][c + 3..c + 6].copy_from_slice(d[a].cross(&(self.cd[t][a] * gt[t])).as_slice());
                }
            }
            rows
        });
        let mut qd = Vector4::zeros();
        if let (Some(vel), Some(rows)) = (&vel, &shear_rows) {
            let rate = Vector4::from(dots24::<4>(rows, vel));
            qd = self.shear_metric * rate * (sec.shear * eta);
            power += qd.dot(&rate);
            qv += qd;
        }
        if let Some(w) = work.as_deref_mut() {
            w.strain[24..28].copy_from_slice(gam.as_slice());
            w.stress[24..28].copy_from_slice(qd.as_slice());
        }
        self.add_shear_forces(&qv, &gt, &dt, &mut f_x, &mut f_d);
        let qv = match mixed {
            Some(st) => {
                let mut qg = Vector4::from(st.shear);
                if consistent {
                    qg += qd;
                }
                self.add_shear_forces(&qg, &gt, &dt, &mut gf_x, &mut gf_d);
                qg
            }
            None => qv,
        };
        if let (Some(btil), Some(rows)) = (btil_rows.as_mut(), &shear_rows) {
            for t in 0..4 {
                for a in 0..4 {
                    for bb in 0..4 {
                        sxd[a][bb] += qv[t] * self.cg[t][a] * self.cd[t][bb];
                    }
                }
            }
            let sk = sec.shear.sqrt();
            put_rows(btil, n_rows, &self.shear_factor, rows, sk);
            if let Some(bdot) = bdot_rows.as_mut() {
                // d(rate_t)/dx_b = cg_tb (sum cd_ta w_a x d_a), d(rate_t)/dtheta_b = cd_tb d_b x
                // (sum cg_ta v_a + g_t x w_b).
                let mut rrows = [[0.0; DOFS_PER_ELEMENT]; 4];
                for t in 0..4 {
                    let (vgt, ddt) = self.tying_vectors(t, &vv, &dd);
                    for a in 0..4 {
                        let c = 6 * a;
                        rrows[t][c..c + 3].copy_from_slice((self.cg[t][a] * ddt).as_slice());
                        let rot = d[a].cross(&(self.cd[t][a] * (vgt + gt[t].cross(&ww[a]))));
                        rrows[t][c + 3..c + 6].copy_from_slice(rot.as_slice());
                    }
                }
                put_rows(bdot, n_rows, &self.shear_factor, &rrows, sk);
            }
            n_rows += 4;
        }

        // Drilling.
        let xc = centre_gradient(&self.dn_centre, x);
        let vc = bdot_rows
            .is_some()
            .then(|| centre_gradient(&self.dn_centre, &vv));
        let kd = sec.drilling * self.area * 0.25;
        for a in 0..4 {
            let (c0, s0) = self.drill_ref[a];
            let (u, v) = self.drill_vectors(a, &xc);
            let psi = 0.5 * (t1[a].dot(&u) - t2[a].dot(&v)) - self.psi0[a];
            let mut big_psi = kd * psi;
            energy += 0.5 * kd * psi * psi;
            let mut row = [0.0; DOFS_PER_ELEMENT];
            // d(psi)/dx_b = al t1 + be t2: the drilling row's translational blocks.
            let mut coef = [(0.0, 0.0); 4];
            let mut gx = [Vector3::zeros(); 4];
            for bb in 0..4 {
                let [p, r] = self.dn_centre[bb];
                let (al, be) = (0.5 * (c0 * r - s0 * p), -0.5 * (c0 * p + s0 * r));
                coef[bb] = (al, be);
                gx[bb] = al * t1[a] + be * t2[a];
                row[6 * bb..6 * bb + 3].copy_from_slice(gx[bb].as_slice());
            }
            row[6 * a + 3..6 * a + 6].copy_from_slice((0.5 * (t1[a].cross(&u) - t2[a].cross(&v))).as_slice());
            let mut psi_v = 0.0;
            if let Some(vel) = &vel {
                let rate = dot24(&row, vel);
                power += kd * eta * rate * rate;
                psi_v = kd * eta * rate;
                big_psi += psi_v;
            }
            if let Some(w) = work.as_deref_mut() {
                (w.strain[28 + a], w.stress[28 + a]) = (psi, psi_v);
            }
            f_t1[a] += 0.5 * big_psi * u;
            f_t2[a] -= 0.5 * big_psi * v;
            let geo_psi = mixed.map_or(big_psi, |st| st.drilling[a] + if consistent { psi_v } else { 0.0 });
            if mixed.is_some() {
                gf_t1[a] += 0.5 * geo_psi * u;
                gf_t2[a] -= 0.5 * geo_psi * v;
            }
            for bb in 0..4 {
                let (al, be) = coef[bb];
                f_x[bb] += big_psi * gx[bb];
                if mixed.is_some() {
                    gf_x[bb] += geo_psi * gx[bb];
                }
                sxt1[bb][a] += geo_psi * al;
                sxt2[bb][a] += geo_psi * be;
            }
            if let Some(btil) = btil_rows.as_mut() {
                let sk = kd.sqrt();
                for j in 0..DOFS_PER_ELEMENT {
                    btil[j * N_ROWS + n_rows] = sk * row[j];
                }
                if let (Some(bdot), Some(vc)) = (bdot_rows.as_mut(), &vc) {
                    // rate = (t1'.u + t1.u' - t2'.v - t2.v') / 2 with t' = w_a x t: d/dx_b =
                    // al t1' + be t2', d/dtheta_a = (t1 x (u' + u x w_a) - t2 x (v' + v x w_a)) / 2.
                    let (dt1, dt2) = (ww[a].cross(&t1[a]), ww[a].cross(&t2[a]));
                    let (du, dv) = self.drill_vectors(a, vc);
                    let rot = 0.5 * (t1[a].cross(&(du + u.cross(&ww[a]))) - t2[a].cross(&(dv + v.cross(&ww[a]))));
                    for bb in 0..4 {
                        let (al, be) = coef[bb];
                        let gxd = al * dt1 + be * dt2;
                        for c in 0..3 {
                            bdot[(6 * bb + c) * N_ROWS + n_rows] = sk * gxd[c];
                        }
                    }
                    for c in 0..3 {
                        bdot[(6 * a + 3 + c) * N_ROWS + n_rows] = sk * rot[c];
                    }
                }
                n_rows += 1;
            }
        }

        // Internal force.
        let mut g_rot = [Vector3::zeros(); 4];
        for a in 0..4 {
            g_rot[a] = d[a].cross(&f_d[a]) + t1[a].cross(&f_t1[a]) + t2[a].cross(&f_t2[a]);
            f.fixed_rows_mut::<3>(6 * a).copy_from(&f_x[a]);
            f.fixed_rows_mut::<3>(6 * a + 3).copy_from(&g_rot[a]);
        }
        // From here on the geometric terms use the geometric stresses.
        if mixed.is_some() {
            for a in 0..4 {
                g_rot[a] = d[a].cross(&gf_d[a]) + t1[a].cross(&gf_t1[a]) + t2[a].cross(&gf_t2[a]);
            }
            (f_x, f_d, f_t1, f_t2) = (gf_x, gf_d, gf_t1, gf_t2);
        }
        if let Some(fg) = f_geo {
            for a in 0..4 {
                fg.fixed_rows_mut::<3>(6 * a).copy_from(&f_x[a]);
                fg.fixed_rows_mut::<3>(6 * a + 3).copy_from(&g_rot[a]);
            }
        }

        // Geometric stiffness and the rotational terms.
        if let (Some(k), Some(btil)) = (k, btil_rows.as_ref()) {
            let material_scale = viscous.map_or(1.0, |v| 1.0 + v.eta * v.gamma_prime);
            debug_assert_eq!(n_rows, N_ROWS);
            if let Some(bdot) = bdot_rows.as_mut() {
                // Material part with viscosity: (1 + eta gamma') B^T C B + eta B^T C d(B v)/dq
                // = Bt^T (s Bt + eta Bt'), not symmetric: every entry by a contiguous dot product.
                // Rotation columns of the velocities' Jacobian beyond gamma' I: the damping matrix
                // times it, Bt J.
                for (a, [jv, jw]) in viscous
                    .map_or([[Matrix3::zeros(); 2]; 4], |v| v.rotation_jacobian)
                    .iter()
                    .enumerate()
                {
                    if jv.iter().chain(jw.iter()).all(|&v| v == 0.0) {
                        continue;
                    }
                    let c = 6 * a;
                    for col in 0..3 {
                        for r in 0..N_ROWS {
                            let mut v = 0.0;
                            for kk in 0..3 {
                                v += btil[(c + kk) * N_ROWS + r] * jv[(kk, col)]
                                    + btil[(c + 3 + kk) * N_ROWS + r] * jw[(kk, col)];
                            }
                            bdot[(c + 3 + col) * N_ROWS + r] += v;
                        }
                    }
                }
                for (bd, b) in bdot.iter_mut().zip(btil) {
                    *bd = material_scale * b + eta * *bd;
                }
                product_into(btil, bdot, k);
            } else {
                // Material part: K = s Bt^T Bt, upper triangle, then mirrored.
                gram_into(btil, material_scale, k);
            }
            for a in 0..4 {
                for bb in 0..4 {
                    let (ra, cb) = (6 * a, 6 * bb);
                    for i in 0..3 {
                        k[(ra + i, cb + i)] += sxx[a][bb];
                    }
                    let kut = -(skew(&d[bb]) * sxd[a][bb] + skew(&t1[bb]) * sxt1[a][bb] + skew(&t2[bb]) * sxt2[a][bb]);
                    let mut blk = k.fixed_view_mut::<3, 3>(ra, cb + 3);
                    blk += kut;
                    let mut blk_t = k.fixed_view_mut::<3, 3>(cb + 3, ra);
                    blk_t += kut.transpose();
                }
                let h = rotated_vector_hessian(&f_d[a], &d[a])
                    + rotated_vector_hessian(&f_t1[a], &t1[a])
                    + rotated_vector_hessian(&f_t2[a], &t2[a])
                    - skew(&g_rot[a]) * 0.5;
                let mut blk = k.fixed_view_mut::<3, 3>(6 * a + 3, 6 * a + 3);
                blk += h;
            }
        }
        (energy, power)
    }
}

/// Rows of `B` (6 x 24: membrane then bending strains) at a Gauss point: derivatives of the
/// strains with respect to the nodal translations and spatial rotation increments.
#[inline]
fn gauss_rows(
    dn: &[[f64; 2]; 4],
    xs: &[Vector3<f64>; 2],
    ds: &[Vector3<f64>; 2],
    d: &[Vector3<f64>; 4],
) -> [[f64; DOFS_PER_ELEMENT]; 6] {
    let mut rows = [[0.0; DOFS_PER_ELEMENT]; 6];
    for a in 0..4 {
        let [p, r] = dn[a];
        let c = 6 * a;
        let bx = [
            p * xs[0],
            r * xs[1],
            p * xs[1] + r * xs[0],
            p * ds[0],
            r * ds[1],
            p * ds[1] + r * ds[0],
        ];
        let bt = [
            d[a].cross(&(p * xs[0])),
            d[a].cross(&(r * xs[1])),
            d[a].cross(&(p * xs[1] + r * xs[0])),
        ];
        for i in 0..3 {
            rows[i][c..c + 3].copy_from_slice(bx[i].as_slice());
            rows[3 + i][c..c + 3].copy_from_slice(bx[3 + i].as_slice());
            rows[3 + i][c + 3..c + 6].copy_from_slice(bt[i].as_slice());
        }
    }
    rows
}

/// Rows of `d(B v)/dq` (6 x 24, as [`gauss_rows`]) at a Gauss point: the derivatives of the
/// membrane and bending strain rates `B v` with respect to the nodal translations and spatial
/// rotation increments at fixed nodal velocities `v_a` and angular velocities `w`, given the
/// surface gradients `vs` of the velocities and `dds` of the director rates `w_a x d_a`. They are
/// the rows of `B` with `(x_,i, d_,i)` replaced by `(v_,i, (w x d)_,i)`, plus, in the rotation
/// blocks of the bending rows, `d_a x (c x w_a)` for each combination `c` of `x_,i` (the
/// director rate `w_a x d_a` turns with the director).
#[inline]
fn gauss_rate_rows(
    dn: &[[f64; 2]; 4],
    xs: &[Vector3<f64>; 2],
    vs: &[Vector3<f64>; 2],
    dds: &[Vector3<f64>; 2],
    d: &[Vector3<f64>; 4],
    w: &[Vector3<f64>; 4],
) -> [[f64; DOFS_PER_ELEMENT]; 6] {
    let mut rows = gauss_rows(dn, vs, dds, d);
    for a in 0..4 {
        let [p, r] = dn[a];
        let c = 6 * a + 3;
        let cx = [p * xs[0], r * xs[1], p * xs[1] + r * xs[0]];
        for i in 0..3 {
            let extra = d[a].cross(&cx[i].cross(&w[a]));
            for k in 0..3 {
                rows[3 + i][c + k] += extra[k];
            }
        }
    }
    rows
}

/// `k = s Bt^T Bt` (symmetric) for the strain rows `btil`, column-major by DOF as the kernel
/// builds them: each entry is exactly [`dot_rows`] of its two columns times `s`, computed four
/// entries of a column at a time in independent registers (the dot products' eight lanes each),
/// which vectorises where the dot products one by one compiled to scalar code; with AVX2 where
/// the CPU has it (detected at run time). Same values to the bit on every path.
fn gram_into(btil: &[f64; DOFS_PER_ELEMENT * N_ROWS], s: f64, k: &mut ElementMatrix) {
    let bt = row_major(btil);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked above), all `gram_avx2` requires.
        unsafe { gram_avx2(&bt, s, k) };
        return;
    }
    gram_blocks(&bt, s, k);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn gram_avx2(bt: &[f64; DOFS_PER_ELEMENT * N_ROWS], s: f64, k: &mut ElementMatrix) {
    gram_blocks(bt, s, k);
}

/// `k = Bt^T Bd` (not symmetric) for the strain rows `btil` and `bdot`, column-major by DOF:
/// each entry is exactly [`dot_rows`] of column `i` of `btil` and column `j` of `bdot`, computed
/// as [`gram_into`] computes its entries (four of a column at a time, in the dot products' eight
/// lanes; AVX2 where the CPU has it): the viscous material tangent, where the dot products one
/// by one took about half of the dynamic tangent's time on the set-up's tapes.
fn product_into(
    btil: &[f64; DOFS_PER_ELEMENT * N_ROWS],
    bdot: &[f64; DOFS_PER_ELEMENT * N_ROWS],
    k: &mut ElementMatrix,
) {
    let (bt, bd) = (row_major(btil), row_major(bdot));
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked above), all `product_avx2` requires.
        unsafe { product_avx2(&bt, &bd, k) };
        return;
    }
    product_blocks(&bt, &bd, k);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn product_avx2(bt: &[f64; DOFS_PER_ELEMENT * N_ROWS], bd: &[f64; DOFS_PER_ELEMENT * N_ROWS], k: &mut ElementMatrix) {
    product_blocks(bt, bd, k);
}

/// [`product_into`]'s product on the row-major rows `bt`, `bd` (see [`gram_blocks`]).
#[inline(always)]
fn product_blocks(bt: &[f64; DOFS_PER_ELEMENT * N_ROWS], bd: &[f64; DOFS_PER_ELEMENT * N_ROWS], k: &mut ElementMatrix) {
    const W: usize = 4;
    for j in 0..DOFS_PER_ELEMENT {
        for i0 in (0..DOFS_PER_ELEMENT).step_by(W) {
            // acc[l][q]: lane l of the dot product of column i0 + q of `bt` and column j of `bd`.
            let mut acc = [[0.0; W]; 8];
            for c in 0..N_ROWS / 8 {
                for (l, lane) in acc.iter_mut().enumerate() {
                    let r = 8 * c + l;
                    let b = bd[r * DOFS_PER_ELEMENT + j];
                    let x: &[f64; W] = bt[r * DOFS_PER_ELEMENT + i0..][..W]
                        .try_into()
                        .expect("i0 + W <= 24");
                    for q in 0..W {
                        lane[q] += x[q] * b;
                    }
                }
            }
            let col = &mut k.as_mut_slice()[j * DOFS_PER_ELEMENT + i0..][..W];
            for (q, v) in col.iter_mut().enumerate() {
                let a = |l: usize| acc[l][q];
                *v = ((a(0) + a(1)) + (a(2) + a(3))) + ((a(4) + a(5)) + (a(6) + a(7)));
            }
        }
    }
}

/// The strain rows `btil` (column-major by DOF) row-major by strain row, so that the entries of
/// a block of [`gram_blocks`] are contiguous.
fn row_major(btil: &[f64; DOFS_PER_ELEMENT * N_ROWS]) -> [f64; DOFS_PER_ELEMENT * N_ROWS] {
    let mut bt = [0.0; DOFS_PER_ELEMENT * N_ROWS];
    for j in 0..DOFS_PER_ELEMENT {
        for r in 0..N_ROWS {
            bt[r * DOFS_PER_ELEMENT + j] = btil[j * N_ROWS + r];
        }
    }
    bt
}

/// [`gram_into`]'s product on the row-major rows `bt` (inlined into each instruction-set
/// variant). No fused multiply-adds: the compiler does not contract `a * b + c` by itself.
#[inline(always)]
fn gram_blocks(bt: &[f64; DOFS_PER_ELEMENT * N_ROWS], s: f64, k: &mut ElementMatrix) {
    const W: usize = 4;
    for j in 0..DOFS_PER_ELEMENT {
        for i0 in (0..=j).step_by(W) {
            // acc[l][q]: lane l of the dot product of columns i0 + q and j (as `dot_rows`).
            let mut acc = [[0.0; W]; 8];
            for c in 0..N_ROWS / 8 {
                for (l, lane) in acc.iter_mut().enumerate() {
                    let row = &bt[(8 * c + l) * DOFS_PER_ELEMENT..][..DOFS_PER_ELEMENT];
                    let b = row[j];
                    let x: &[f64; W] = row[i0..i0 + W].try_into().expect("i0 + W <= 24");
                    for q in 0..W {
                        lane[q] += x[q] * b;
                    }
                }
            }
            let mut sum = [0.0; W];
            for (q, v) in sum.iter_mut().enumerate() {
                let a = |l: usize| acc[l][q];
                *v = s * (((a(0) + a(1)) + (a(2) + a(3))) + ((a(4) + a(5)) + (a(6) + a(7))));
            }
            let n = W.min(j + 1 - i0);
            k.as_mut_slice()[j * DOFS_PER_ELEMENT + i0..][..n].copy_from_slice(&sum[..n]);
        }
    }
    for j in 0..DOFS_PER_ELEMENT {
        for i in 0..j {
            k[(j, i)] = k[(i, j)];
        }
    }
}

/// Dot product of two strain-row columns of length [`N_ROWS`], in independent lanes so that the
/// reduction vectorises without reassociation.
/// (The reference the blocked products are tested against.)
#[cfg(test)]
fn dot_rows(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 8];
    for (ci, cj) in a.chunks_exact(8).zip(b.chunks_exact(8)) {
        for l in 0..8 {
            acc[l] += ci[l] * cj[l];
        }
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]))
}

/// Writes `scale * factor * rows` (`factor` upper triangular) into the rows `offset..offset + R`
/// of the column-major (by DOF) row block `out`.
#[inline]
fn put_rows<const R: usize>(
    out: &mut [f64; DOFS_PER_ELEMENT * N_ROWS],
    offset: usize,
    factor: &SMatrix<f64, R, R>,
    rows: &[[f64; DOFS_PER_ELEMENT]],
    scale: f64,
) {
    for i in 0..R {
        for j in 0..DOFS_PER_ELEMENT {
            let mut v = 0.0;
            for kk in i..R {
                v += factor[(i, kk)] * rows[kk][j];
            }
            out[j * N_ROWS + offset + i] = scale * v;
        }
    }
}

#[inline]
fn gradients(
    dn: &[[f64; 2]; 4],
    x: &[Vector3<f64>; 4],
    d: &[Vector3<f64>; 4],
) -> ([Vector3<f64>; 2], [Vector3<f64>; 2]) {
    let mut xs = [Vector3::zeros(); 2];
    let mut ds = [Vector3::zeros(); 2];
    for a in 0..4 {
        for i in 0..2 {
            xs[i] += dn[a][i] * x[a];
            ds[i] += dn[a][i] * d[a];
        }
    }
    (xs, ds)
}

/// Adds the force gradients (with respect to `x_a` and `d_a`) of the weighted membrane forces `n`
/// and bending moments `m` at a Gauss point with shape-function derivatives `dn` and surface
/// gradients `xs`, `ds`.
#[inline]
fn add_gauss_forces(
    dn: &[[f64; 2]; 4],
    xs: &[Vector3<f64>; 2],
    ds: &[Vector3<f64>; 2],
    n: &Vector3<f64>,
    m: &Vector3<f64>,
    f_x: &mut [Vector3<f64>; 4],
    f_d: &mut [Vector3<f64>; 4],
) {
    for a in 0..4 {
        let [p, r] = dn[a];
        f_x[a] += n[0] * p * xs[0]
            + n[1] * r * xs[1]
            + n[2] * (p * xs[1] + r * xs[0])
            + m[0] * p * ds[0]
            + m[1] * r * ds[1]
            + m[2] * (p * ds[1] + r * ds[0]);
        f_d[a] += m[0] * p * xs[0] + m[1] * r * xs[1] + m[2] * (p * xs[1] + r * xs[0]);
    }
}

#[inline]
fn centre_gradient(dn: &[[f64; 2]; 4], x: &[Vector3<f64>; 4]) -> [Vector3<f64>; 2] {
    let mut xs = [Vector3::zeros(); 2];
    for a in 0..4 {
        xs[0] += dn[a][0] * x[a];
        xs[1] += dn[a][1] * x[a];
    }
    xs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::ShellSection;
    use crate::rotation::rotate;
    use nalgebra::UnitQuaternion;

    /// A warped, curved quadrilateral with nodal triads from its corner normals.
    fn sample() -> ([Vector3<f64>; 4], [UnitQuaternion<f64>; 4], ShellElement) {
        let x = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(2.1e-3, 0.1e-3, 0.2e-3),
            Vector3::new(2.3e-3, 1.9e-3, 0.5e-3),
            Vector3::new(-0.2e-3, 2.0e-3, 0.1e-3),
        ];
        let q = std::array::from_fn(|a| {
            let n = (x[(a + 1) % 4] - x[a])
                .cross(&(x[(a + 3) % 4] - x[a]))
                .normalize();
            let t1 = (Vector3::x() - n * n.x).normalize();
            let t2 = n.cross(&t1);
            UnitQuaternion::from_matrix(&Matrix3::from_columns(&[t1, t2, n]))
        });
        let m = q.map(|qa: UnitQuaternion<f64>| qa.to_rotation_matrix().into_inner());
        let e = ShellElement::try_new([0, 1, 2, 3], &x, &m).unwrap();
        (x, q, e)
    }

    fn section() -> SectionStiffness {
        ShellSection {
            drilling_factor: 0.1,
            ..ShellSection::new(0.138e-3, 151.76e9, 0.3)
        }
        .stiffness()
    }

    fn deformed(
        x0: &[Vector3<f64>; 4],
        q0: &[UnitQuaternion<f64>; 4],
    ) -> ([Vector3<f64>; 4], [UnitQuaternion<f64>; 4]) {
        let du = [
            Vector3::new(1e-5, -2e-5, 3e-4),
            Vector3::new(-2e-5, 1e-5, -1e-4),
            Vector3::new(3e-5, 2e-5, 2e-4),
            Vector3::new(0.0, -1e-5, -3e-4),
        ];
        let th = [
            Vector3::new(0.3, -0.2, 0.1),
            Vector3::new(-0.1, 0.4, 0.05),
            Vector3::new(0.2, 0.1, -0.3),
            Vector3::new(0.0, -0.3, 0.2),
        ];
        (
            std::array::from_fn(|a| x0[a] + du[a]),
            std::array::from_fn(|a| rotate(&q0[a], &th[a])),
        )
    }

    fn mats(q: &[UnitQuaternion<f64>; 4]) -> [Matrix3<f64>; 4] {
        q.map(|qa| qa.to_rotation_matrix().into_inner())
    }

    fn perturb(
        x: &[Vector3<f64>; 4],
        q: &[UnitQuaternion<f64>; 4],
        j: usize,
        h: f64,
    ) -> ([Vector3<f64>; 4], [UnitQuaternion<f64>; 4]) {
        let (mut x, mut q) = (*x, *q);
        let (a, c) = (j / 6, j % 6);
        if c < 3 {
            x[a][c] += h;
        } else {
            q[a] = rotate(&q[a], &Vector3::ith(c - 3, h));
        }
        (x, q)
    }

    /// Deterministic pseudo-random numbers of magnitudes 1e-6 to 1e6 (either sign), so that a
    /// different summation order would show in the last bits.
    fn mixed_magnitudes(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi((seed % 13) as i32 - 6)
        }
    }

    /// The interleaved dot products are the one-by-one dot products to the bit.
    #[test]
    fn interleaved_dot_products_are_the_dot_products_to_the_bit() {
        let mut next = mixed_magnitudes(0x2545_f491_4f6c_dd1d);
        let mut rows = [[0.0; DOFS_PER_ELEMENT]; 6];
        let mut b = [0.0; DOFS_PER_ELEMENT];
        for v in rows.iter_mut().flatten().chain(b.iter_mut()) {
            *v = next();
        }
        rows[5] = [-0.0; DOFS_PER_ELEMENT];
        let six: [f64; 6] = dots24(&rows, &b);
        let four: [f64; 4] = dots24(&rows, &b);
        for i in 0..6 {
            assert_eq!(six[i].to_bits(), dot24(&rows[i], &b).to_bits(), "row {i}");
        }
        for i in 0..4 {
            assert_eq!(four[i].to_bits(), dot24(&rows[i], &b).to_bits(), "row {i}");
        }
    }

    /// The blocked Gram product gives every entry of `s Bt^T Bt` exactly as the dot products one
    /// by one do (the same products and sums in the same order), on every instruction set.
    #[test]
    fn gram_product_is_the_dot_products_to_the_bit() {
        let mut next = mixed_magnitudes(0x9e37_79b9_7f4a_7c15);
        let btil: [f64; DOFS_PER_ELEMENT * N_ROWS] = std::array::from_fn(|_| next());
        let s = 1.000_173;
        let mut k = ElementMatrix::zeros();
        gram_into(&btil, s, &mut k);
        let bt = row_major(&btil);
        let mut k_generic = ElementMatrix::zeros();
        gram_blocks(&bt, s, &mut k_generic);
        for i in 0..DOFS_PER_ELEMENT {
            for j in 0..DOFS_PER_ELEMENT {
                let expected = s * dot_rows(&btil[i * N_ROWS..(i + 1) * N_ROWS], &btil[j * N_ROWS..(j + 1) * N_ROWS]);
                assert_eq!(k[(i, j)].to_bits(), expected.to_bits(), "({i}, {j})");
                assert_eq!(k_generic[(i, j)].to_bits(), expected.to_bits(), "({i}, {j})");
            }
        }
    }

    /// The blocked non-symmetric product gives every entry of `Bt^T Bd` exactly as the dot
    /// products one by one do, on every instruction set.
    #[test]
    fn product_is_the_dot_products_to_the_bit() {
        let mut next = mixed_magnitudes(0x3c6e_f372_fe94_f82b);
        let btil: [f64; DOFS_PER_ELEMENT * N_ROWS] = std::array::from_fn(|_| next());
        let bdot: [f64; DOFS_PER_ELEMENT * N_ROWS] = std::array::from_fn(|_| next());
        let mut k = ElementMatrix::zeros();
        product_into(&btil, &bdot, &mut k);
        let mut k_generic = ElementMatrix::zeros();
        product_blocks(&row_major(&btil), &row_major(&bdot), &mut k_generic);
        for i in 0..DOFS_PER_ELEMENT {
            for j in 0..DOFS_PER_ELEMENT {
                let expected = dot_rows(&btil[i * N_ROWS..(i + 1) * N_ROWS], &bdot[j * N_ROWS..(j + 1) * N_ROWS]);
                assert_eq!(k[(i, j)].to_bits(), expected.to_bits(), "({i}, {j})");
                assert_eq!(k_generic[(i, j)].to_bits(), expected.to_bits(), "({i}, {j})");
            }
        }
    }

    #[test]
    fn reference_state_is_stress_free() {
        let (x, q, e) = sample();
        let mut f = ElementVector::zeros();
        let energy = e.compute_into(&x, &mats(&q), &section(), &mut f, None);
        assert!(
            energy.abs() < 1e-20 && f.norm() < 1e-12,
            "energy {energy}, |f| {}",
            f.norm()
        );
    }

    #[test]
    fn internal_force_is_gradient_of_energy() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let sec = section();
        let mut f = ElementVector::zeros();
        e.compute_into(&x, &mats(&q), &sec, &mut f, None);
        for j in 0..24 {
            let h = if j % 6 < 3 { 1e-8 } else { 1e-6 };
            let (xp, qp) = perturb(&x, &q, j, h);
            let (xm, qm) = perturb(&x, &q, j, -h);
            let fd = (e.energy(&xp, &mats(&qp), &sec) - e.energy(&xm, &mats(&qm), &sec)) / (2.0 * h);
            assert!(
                (fd - f[j]).abs() <= 1e-6 * f.amax() + 1e-12,
                "dof {j}: f = {}, fd = {fd}",
                f[j]
            );
        }
    }

    #[test]
    fn stiffness_is_derivative_of_internal_force() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let sec = section();
        let mut f = ElementVector::zeros();
        let mut k = ElementMatrix::zeros();
        e.compute_into(&x, &mats(&q), &sec, &mut f, Some(&mut k));
        let mut worst: f64 = 0.0;
        for j in 0..24 {
            let h = if j % 6 < 3 { 1e-9 } else { 1e-7 };
            let (xp, qp) = perturb(&x, &q, j, h);
            let (xm, qm) = perturb(&x, &q, j, -h);
            let (mut fp, mut fm) = (ElementVector::zeros(), ElementVector::zeros());
            e.compute_into(&xp, &mats(&qp), &sec, &mut fp, None);
            e.compute_into(&xm, &mats(&qm), &sec, &mut fm, None);
            let col = (fp - fm) / (2.0 * h);
            for i in 0..24 {
                // Scale each entry by its row/column units so that translations and rotations compare.
                let scale = (k[(i, i)].abs() * k[(j, j)].abs()).sqrt();
                worst = worst.max((col[i] - k[(i, j)]).abs() / scale);
            }
        }
        assert!(worst < 1e-6, "max relative tangent error {worst:e}");
    }

    /// `sum stress . strain` over all strain rows.
    fn pairing(st: &ElementStress, s: &ShellStrains) -> f64 {
        let mut v = 0.0;
        for p in 0..4 {
            for i in 0..3 {
                v += st.membrane[p][i] * s.membrane[p][i] + st.bending[p][i] * s.bending[p][i];
            }
        }
        (0..4)
            .map(|t| st.shear[t] * s.shear[t] + st.drilling[t] * s.drilling[t])
            .sum::<f64>()
            + v
    }

    #[test]
    fn mixed_tangent_with_the_own_stresses_is_the_tangent() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let (sec, m) = (section(), mats(&q));
        let own = e.linearised_stress(&x, &m, &sec, &[Vector3::zeros(); 4], &[Vector3::zeros(); 4]);
        let (mut f, mut k) = (ElementVector::zeros(), ElementMatrix::zeros());
        e.compute_into(&x, &m, &sec, &mut f, Some(&mut k));
        let (mut fm, mut km, mut fg) = (ElementVector::zeros(), ElementMatrix::zeros(), ElementVector::zeros());
        e.compute_mixed_into(&x, &m, &sec, Some(&own), &mut fm, Some(&mut km), Some(&mut fg));
        assert_mixed_is_plain(&(f, k), &(fm, km, fg));
    }

    /// The mixed iteration with the element's own stresses gives the plain force, geometric force
    /// and tangent, to round-off (the same arithmetic up to the order of a few sums).
    fn assert_mixed_is_plain(
        (f, k): &(ElementVector, ElementMatrix),
        (fm, km, fg): &(ElementVector, ElementMatrix, ElementVector),
    ) {
        let (df, dg, dk) = ((fm - f).amax(), (fg - f).amax(), (km - k).amax());
        assert!(df <= 1e-12 * f.amax(), "force differs by {df}");
        assert!(dg <= 1e-10 * f.amax(), "geometric force differs by {dg}");
        assert!(dk <= 1e-10 * k.amax(), "tangent differs by {dk}");
    }

    #[test]
    fn linearised_stress_is_exact_to_first_order() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let sec = section();
        let dx = [
            Vector3::new(2e-5, -1e-5, 4e-5),
            Vector3::new(-1e-5, 3e-5, 1e-5),
            Vector3::new(1e-5, 1e-5, -5e-5),
            Vector3::new(-3e-5, 2e-5, 2e-5),
        ];
        let dth = [
            Vector3::new(0.02, -0.01, 0.03),
            Vector3::new(-0.01, 0.02, 0.01),
            Vector3::new(0.03, 0.01, -0.02),
            Vector3::new(0.01, -0.03, 0.02),
        ];
        let zero = [Vector3::zeros(); 4];
        let flat = |st: &ElementStress| -> Vec<f64> {
            let mut v: Vec<f64> = st
                .membrane
                .iter()
                .chain(&st.bending)
                .flatten()
                .copied()
                .collect();
            v.extend(st.shear.iter().chain(&st.drilling));
            v
        };
        let s0 = flat(&e.linearised_stress(&x, &mats(&q), &sec, &zero, &zero));
        let mut errors = Vec::new();
        for h in [1.0, 0.5, 0.25] {
            let xh: [Vector3<f64>; 4] = std::array::from_fn(|a| x[a] + h * dx[a]);
            let qh: [UnitQuaternion<f64>; 4] = std::array::from_fn(|a| rotate(&q[a], &(h * dth[a])));
            let exact = flat(&e.linearised_stress(&xh, &mats(&qh), &sec, &zero, &zero));
            let hdx = dx.map(|v| h * v);
            let hdth = dth.map(|v| h * v);
            let lin = flat(&e.linearised_stress(&x, &mats(&q), &sec, &hdx, &hdth));
            let change = exact
                .iter()
                .zip(&s0)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let err = exact
                .iter()
                .zip(&lin)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                err < 0.2 * change,
                "h = {h}: linearisation error {err:e} vs change {change:e}"
            );
            errors.push(err);
        }
        // Second-order remainder: halving the increment divides the error by about 4.
        for w in errors.windows(2) {
            let rate = (w[0] / w[1]).log2();
            assert!((rate - 2.0).abs() < 0.15, "remainder order {rate}, errors {errors:?}");
        }
    }

    #[test]
    fn mixed_tangent_is_derivative_of_the_geometric_force() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let sec = section();
        let zero = [Vector3::zeros(); 4];
        // Stresses unrelated to the configuration (those of another state, scaled).
        let (xo, qo) = deformed(&x, &q);
        let mut st = e.linearised_stress(&xo, &mats(&qo), &sec, &zero, &zero);
        st.drilling = [3.0e-3, -2.0e-3, 1.0e-3, 4.0e-3];
        let geo_force = |xx: &[Vector3<f64>; 4], qq: &[UnitQuaternion<f64>; 4]| {
            let (mut f, mut fg) = (ElementVector::zeros(), ElementVector::zeros());
            e.compute_mixed_into(xx, &mats(qq), &sec, Some(&st), &mut f, None, Some(&mut fg));
            fg
        };
        // f_geo is the gradient of stress . strain(q) at fixed stress.
        let fg = geo_force(&x, &q);
        for j in 0..24 {
            let h = if j % 6 < 3 { 1e-8 } else { 1e-6 };
            let (xp, qp) = perturb(&x, &q, j, h);
            let (xm, qm) = perturb(&x, &q, j, -h);
            let fd =
                (pairing(&st, &e.strains(&xp, &mats(&qp))) - pairing(&st, &e.strains(&xm, &mats(&qm)))) / (2.0 * h);
            assert!(
                (fd - fg[j]).abs() <= 1e-6 * fg.amax(),
                "dof {j}: f_geo {}, fd {fd}",
                fg[j]
            );
        }
        // Mixed tangent = material part (zero stress) + derivative of f_geo at fixed stress.
        let (mut f, mut k, mut k0) = (ElementVector::zeros(), ElementMatrix::zeros(), ElementMatrix::zeros());
        e.compute_mixed_into(&x, &mats(&q), &sec, Some(&st), &mut f, Some(&mut k), None);
        e.compute_mixed_into(
            &x,
            &mats(&q),
            &sec,
            Some(&ElementStress::default()),
            &mut f,
            Some(&mut k0),
            None,
        );
        let geometric = k - k0;
        let mut worst: f64 = 0.0;
        for j in 0..24 {
            let h = if j % 6 < 3 { 1e-9 } else { 1e-7 };
            let (xp, qp) = perturb(&x, &q, j, h);
            let (xm, qm) = perturb(&x, &q, j, -h);
            let col = (geo_force(&xp, &qp) - geo_force(&xm, &qm)) / (2.0 * h);
            for i in 0..24 {
                let scale = (k[(i, i)].abs() * k[(j, j)].abs()).sqrt();
                worst = worst.max((col[i] - geometric[(i, j)]).abs() / scale);
            }
        }
        assert!(worst < 1e-6, "max relative error of the geometric tangent {worst:e}");
    }

    #[test]
    fn rigid_body_motion_gives_zero_internal_force() {
        let (x0, q0, e) = sample();
        let rot = UnitQuaternion::from_scaled_axis(Vector3::new(0.7, -1.9, 2.4));
        let shift = Vector3::new(0.3, -0.1, 0.2);
        let x: [Vector3<f64>; 4] = std::array::from_fn(|a| rot * x0[a] + shift);
        let q: [UnitQuaternion<f64>; 4] = std::array::from_fn(|a| rot * q0[a]);
        let mut f = ElementVector::zeros();
        let energy = e.compute_into(&x, &mats(&q), &section(), &mut f, None);
        let (mut f_scale, mut k) = (ElementVector::zeros(), ElementMatrix::zeros());
        let (xd, qd) = deformed(&x0, &q0);
        e.compute_into(&xd, &mats(&qd), &section(), &mut f_scale, Some(&mut k));
        assert!(energy.abs() < 1e-18, "energy {energy}");
        assert!(
            f.amax() < 1e-9 * f_scale.amax(),
            "|f| = {} vs deformed {}",
            f.amax(),
            f_scale.amax()
        );
    }

    /// Kelvin-Voigt: a rigid velocity field (translation plus spin about any point) has no strain
    /// rate, so it dissipates nothing and adds no force; for a deforming one the dissipated power
    /// is the viscous force's power, and it is positive.
    #[test]
    fn viscous_stresses_see_only_strain_rates() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let sec = section();
        let mut f_el = ElementVector::zeros();
        e.compute_into(&x, &mats(&q), &sec, &mut f_el, None);
        let spin = Vector3::new(3.0, -2.0, 5.0);
        let rigid = Viscous {
            v: std::array::from_fn(|a| {
                Vector3::new(0.1, 0.2, -0.3) + spin.cross(&(x[a] - Vector3::new(1.0, 2.0, 0.5)))
            }),
            w: [spin; 4],
            eta: 0.01,
            gamma_prime: 0.0,
            rotation_jacobian: Default::default(),
            consistent: false,
        };
        let mut f = ElementVector::zeros();
        let (_, power) = e.compute_viscous_into(&x, &mats(&q), &sec, &rigid, &mut f, None, None);
        let scale = f_el.norm() * 0.01 * spin.norm();
        assert!(power.abs() < 1e-12 * scale, "rigid motion dissipates {power:e} W");
        assert!((f - f_el).norm() < 1e-10 * scale, "rigid motion adds viscous forces");
        let mut deforming = rigid;
        deforming.v[2] += Vector3::new(0.0, 0.0, 0.4);
        deforming.w[1] += Vector3::new(0.0, 7.0, 0.0);
        let (_, power) = e.compute_viscous_into(&x, &mats(&q), &sec, &deforming, &mut f, None, None);
        let vel = ElementVector::from_column_slice(&deforming.velocity());
        let viscous_power = (f - f_el).dot(&vel);
        assert!(
            power > 0.0 && (viscous_power - power).abs() < 1e-9 * power,
            "{viscous_power} vs {power}"
        );
    }

    /// Nodal velocities and angular velocities of a deforming motion (strain rates ~ 100 / s, so
    /// that with eta = 2e-3 s the viscous stresses are a fifth of the elastic ones).
    fn moving(eta: f64, gamma_prime: f64) -> Viscous {
        Viscous {
            v: [
                Vector3::new(0.3, -0.1, 0.2),
                Vector3::new(-0.2, 0.4, -0.3),
                Vector3::new(0.1, 0.2, 0.5),
                Vector3::new(0.0, -0.3, -0.1),
            ],
            w: [
                Vector3::new(40.0, -70.0, 20.0),
                Vector3::new(-30.0, 50.0, 90.0),
                Vector3::new(60.0, 10.0, -40.0),
                Vector3::new(-20.0, -80.0, 30.0),
            ],
            eta,
            gamma_prime,
            rotation_jacobian: Default::default(),
            consistent: true,
        }
    }

    /// Largest error of `k` against central differences of the Kelvin-Voigt force in the
    /// configuration, the velocities moving by `gamma'` times the increment, each entry scaled by
    /// the diagonal of `k` in its row and column (translations and rotations compare).
    fn viscous_tangent_error(
        e: &ShellElement,
        x: &[Vector3<f64>; 4],
        q: &[UnitQuaternion<f64>; 4],
        viscous: &Viscous,
        k: &ElementMatrix,
    ) -> f64 {
        let sec = section();
        let mut worst: f64 = 0.0;
        for j in 0..DOFS_PER_ELEMENT {
            let h = if j % 6 < 3 { 1e-8 } else { 1e-6 };
            let force = |sign: f64| {
                let (xp, qp) = perturb(x, q, j, sign * h);
                let mut v = *viscous;
                let (a, c) = (j / 6, j % 6);
                let rate = sign * h * viscous.gamma_prime;
                if c < 3 {
                    v.v[a][c] += rate;
                } else {
                    let [jv, jw] = viscous.rotation_jacobian[a];
                    v.w[a][c - 3] += rate;
                    v.v[a] += sign * h * jv.column(c - 3);
                    v.w[a] += sign * h * jw.column(c - 3);
                }
                let mut fp = ElementVector::zeros();
                e.compute_viscous_into(&xp, &mats(&qp), &sec, &v, &mut fp, None, None);
                fp
            };
            let col = (force(1.0) - force(-1.0)) / (2.0 * h);
            for i in 0..DOFS_PER_ELEMENT {
                let scale = (k[(i, i)].abs() * k[(j, j)].abs()).sqrt();
                worst = worst.max((col[i] - k[(i, j)]).abs() / scale);
            }
        }
        worst
    }

    /// The tangent of the Kelvin-Voigt force of a moving, curved, distorted element is its
    /// derivative in the configuration at fixed velocities and angular velocities (`gamma' = 0`:
    /// only the geometric part of the total stresses and `B^T C eta d(B v)/dq` remain besides the
    /// elastic tangent), and with `gamma' > 0` the damping matrix joins, times the velocities'
    /// rotation Jacobian when it is not `gamma' I`. Central differences with
    /// steps 1e-8 m / 1e-6 rad: truncation and round-off ~1e-8 of the scaled entries (the error
    /// stays there from steps 1e-9 m to 1e-7 m); without `d(B v)/dq` it is 2.
    #[test]
    fn viscous_tangent_is_derivative_at_fixed_velocities() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let sec = section();
        let (mut f, mut k, mut k_el) = (ElementVector::zeros(), ElementMatrix::zeros(), ElementMatrix::zeros());
        e.compute_into(&x, &mats(&q), &sec, &mut f, Some(&mut k_el));
        // Velocities that also depend on the rotation increments beyond gamma' (as those of a
        // Lie-group integrator and of tied nodes do).
        let mut jacobians = moving(2e-3, 800.0);
        for (a, jac) in jacobians.rotation_jacobian.iter_mut().enumerate() {
            #[allow(clippy::cast_precision_loss)]
            let s = a as f64 + 1.0;
            jac[0] = Matrix3::new(0.1, -0.3, 0.2, 0.4, 0.0, -0.1, -0.2, 0.3, 0.1) * s;
            jac[1] = Matrix3::new(30.0, -50.0, 10.0, 20.0, -40.0, 60.0, -10.0, 70.0, 50.0) * s;
        }
        for viscous in [moving(2e-3, 0.0), moving(2e-3, 800.0), jacobians] {
            e.compute_viscous_into(&x, &mats(&q), &sec, &viscous, &mut f, Some(&mut k), None);
            let worst = viscous_tangent_error(&e, &x, &q, &viscous, &k);
            assert!(
                worst < 1e-7,
                "gamma' = {}: max relative tangent error {worst:e}",
                viscous.gamma_prime
            );
        }
        // The configuration derivative of the strain rates is not negligible here: the viscous
        // terms at gamma' = 0 change the tangent by far more than the tolerance.
        let viscous = moving(2e-3, 0.0);
        e.compute_viscous_into(&x, &mats(&q), &sec, &viscous, &mut f, Some(&mut k), None);
        let change = (0..DOFS_PER_ELEMENT)
            .flat_map(|i| (0..DOFS_PER_ELEMENT).map(move |j| (i, j)))
            .map(|(i, j)| (k[(i, j)] - k_el[(i, j)]).abs() / (k_el[(i, i)].abs() * k_el[(j, j)].abs()).sqrt())
            .fold(0.0, f64::max);
        assert!(change > 1e-2, "viscous tangent terms {change:e}");
    }

    /// With the elastic stresses of the configuration as the mixed iteration's stresses, the
    /// mixed viscous tangent is the consistent one (the viscous stresses enter the geometric part
    /// in both).
    #[test]
    fn mixed_viscous_tangent_with_the_own_stresses_is_the_tangent() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let (sec, m) = (section(), mats(&q));
        let viscous = moving(2e-3, 800.0);
        let own = e.linearised_stress(&x, &m, &sec, &[Vector3::zeros(); 4], &[Vector3::zeros(); 4]);
        let (mut f, mut k) = (ElementVector::zeros(), ElementMatrix::zeros());
        e.compute_viscous_into(&x, &m, &sec, &viscous, &mut f, Some(&mut k), None);
        let (mut fm, mut km, mut fg) = (ElementVector::zeros(), ElementMatrix::zeros(), ElementVector::zeros());
        e.compute_viscous_mixed_into(&x, &m, &sec, &viscous, &own, &mut fm, &mut km, &mut fg, None);
        assert_mixed_is_plain(&(f, k), &(fm, km, fg));
    }

    /// At rest, the tangent of the Kelvin-Voigt force with velocities `gamma' delta` is the
    /// elastic tangent plus `eta gamma'` times its material part (finite differences).
    #[test]
    fn viscous_tangent_at_rest_matches_finite_differences() {
        let (x0, q0, e) = sample();
        let (x, q) = deformed(&x0, &q0);
        let sec = section();
        let (eta, gamma_prime) = (2e-3, 800.0);
        let at_rest = Viscous {
            eta,
            gamma_prime,
            ..Viscous::default()
        };
        let mut f = ElementVector::zeros();
        let mut k = ElementMatrix::zeros();
        e.compute_viscous_into(&x, &mats(&q), &sec, &at_rest, &mut f, Some(&mut k), None);
        let h = 1e-7;
        for j in 0..DOFS_PER_ELEMENT {
            let force = |sign: f64| {
                let (xp, qp) = perturb(&x, &q, j, sign * h);
                let mut v = at_rest;
                let rate = sign * h * gamma_prime;
                if j % 6 < 3 {
                    v.v[j / 6][j % 6] = rate;
                } else {
                    v.w[j / 6][j % 6 - 3] = rate;
                }
                let mut fp = ElementVector::zeros();
                e.compute_viscous_into(&xp, &mats(&qp), &sec, &v, &mut fp, None, None);
                fp
            };
            let fd = (force(1.0) - force(-1.0)) / (2.0 * h);
            let err = (fd - k.column(j)).norm() / k.column(j).norm();
            // Measured: at most 6e-9.
            assert!(err < 1e-7, "column {j}: relative error {err:e}");
        }
    }
}

//! Gauss rules on the bi-unit square.

/// Abscissa of the 2-point Gauss rule, 1/sqrt(3).
pub const G2: f64 = 0.577_350_269_189_625_8;

/// The 2x2 Gauss points `(xi, eta)`, all of weight 1, in the node order of the quadrilateral.
pub const GAUSS_2X2: [(f64, f64); 4] = [(-G2, -G2), (G2, -G2), (G2, G2), (-G2, G2)];

/// Bilinear shape functions `N_a(xi, eta)` and their derivatives `[dN_a/dxi, dN_a/deta]`.
#[inline]
#[must_use]
pub fn bilinear(xi: f64, eta: f64) -> ([f64; 4], [[f64; 2]; 4]) {
    const XA: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];
    const EA: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];
    let mut n = [0.0; 4];
    let mut dn = [[0.0; 2]; 4];
    for a in 0..4 {
        n[a] = 0.25 * (1.0 + XA[a] * xi) * (1.0 + EA[a] * eta);
        dn[a] = [0.25 * XA[a] * (1.0 + EA[a] * eta), 0.25 * EA[a] * (1.0 + XA[a] * xi)];
    }
    (n, dn)
}

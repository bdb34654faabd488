//! Structured mesh generators: flat plate, cylindrical panel and tape spring.

use nalgebra::Vector3;

use super::Mesh;
use crate::error::{check_positive, shown, Error, Result};

/// Structured grid of `nx * ny` quadrilaterals over a parametric rectangle, mapped by `place(s, r)`
/// with `s, r` in `[0, 1]`. Node `(i, j)` has index `j * (nx + 1) + i`.
fn grid(nx: usize, ny: usize, place: impl Fn(f64, f64) -> Vector3<f64>) -> Result<Mesh> {
    if nx == 0 || ny == 0 {
        return Err(Error::InvalidParameter(format!(
            "element counts must be >= 1 (got {nx} x {ny})"
        )));
    }
    // Sizes are checked before the allocation, which would abort the process if it failed.
    let n_nodes = (nx.checked_add(1)).and_then(|a| ny.checked_add(1).and_then(|b| a.checked_mul(b)));
    crate::memory::check_mesh(n_nodes, nx.checked_mul(ny))?;
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            nodes.push(place(i as f64 / nx as f64, j as f64 / ny as f64));
        }
    }
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut quads = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mut mesh = Mesh::try_new(nodes, quads)?;
    mesh.add_node_set("s0", (0..=ny).map(|j| id(0, j)).collect())?;
    mesh.add_node_set("s1", (0..=ny).map(|j| id(nx, j)).collect())?;
    mesh.add_node_set("r0", (0..=nx).map(|i| id(i, 0)).collect())?;
    mesh.add_node_set("r1", (0..=nx).map(|i| id(i, ny)).collect())?;
    mesh.add_node_set("all", (0..mesh.n_nodes()).collect())?;
    Ok(mesh)
}

/// Flat rectangular plate `[0, lx] x [0, ly]` in the x-y plane (normal +z), `nx * ny` elements.
///
/// Node sets: `x0`, `x1` (edges x = 0 and x = lx), `y0`, `y1`, `all`.
///
/// # Errors
/// [`Error::InvalidParameter`] for non-positive sizes or zero element counts.
pub fn flat_plate(lx: f64, ly: f64, nx: usize, ny: usize) -> Result<Mesh> {
    check_positive("plate length lx [m]", lx)?;
    check_positive("plate width ly [m]", ly)?;
    let mut mesh = grid(nx, ny, |s, r| Vector3::new(s * lx, r * ly, 0.0))?;
    rename(&mut mesh, &[("s0", "x0"), ("s1", "x1"), ("r0", "y0"), ("r1", "y1")]);
    Ok(mesh)
}

/// Largest angle of a cylindrical panel \[rad\]: beyond it the node angles `phi0 + k dphi` lose
/// their digits (a ulp of 1e16 rad is 2 rad).
pub const MAX_PANEL_ANGLE: f64 = 1e6;

/// Cylindrical panel of radius `radius` about the x axis: points `(x, R sin(phi), R cos(phi))`
/// for `x` in `[0, length]` and `phi` in `[phi0, phi1]` \[rad\]; normals point away from the axis.
///
/// Node sets: `x0`, `x1` (curved edges), `phi0`, `phi1` (straight edges), `all`.
///
/// # Errors
/// [`Error::InvalidParameter`] for non-positive sizes, `phi1 <= phi0`, a span of more than one
/// turn (the panel would lie on itself, layer over layer), an angle beyond
/// [`MAX_PANEL_ANGLE`] or zero element counts.
pub fn cylindrical_panel(radius: f64, length: f64, phi0: f64, phi1: f64, n_axial: usize, n_arc: usize) -> Result<Mesh> {
    check_positive("radius [m]", radius)?;
    check_positive("length [m]", length)?;
    check_positive("angular span phi1 - phi0 [rad]", phi1 - phi0)?;
    for (name, angle) in [("phi0", phi0), ("phi1", phi1)] {
        if angle.abs() > MAX_PANEL_ANGLE {
            return Err(Error::InvalidParameter(format!(
                "{name} = {} rad is beyond {MAX_PANEL_ANGLE:e} rad: the nodes' angles would lose \
                 their digits; give the angles within one turn",
                shown(angle)
            )));
        }
    }
    if phi1 - phi0 > 2.0 * std::f64::consts::PI {
        return Err(Error::InvalidParameter(format!(
            "the angular span phi1 - phi0 = {} rad is more than one turn (2 pi): the panel would lie \
             on itself",
            shown(phi1 - phi0)
        )));
    }
    let mut mesh = grid(n_axial, n_arc, |s, r| {
        let phi = phi0 + r * (phi1 - phi0);
        Vector3::new(s * length, radius * phi.sin(), radius * phi.cos())
    })?;
    rename(&mut mesh, &[("s0", "x0"), ("s1", "x1"), ("r0", "phi0"), ("r1", "phi1")]);
    Ok(mesh)
}

/// Geometry of a tape spring: a straight strip of length `length` along x whose cross-section is a
/// circular arc of radius `radius` subtending `alpha` \[rad\] in the y-z plane, symmetric about z,
/// with its centre of curvature on the +z side (at `z = radius`); the arc's middle lies on the x axis.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TapeGeometry {
    /// Length L \[m\].
    pub length: f64,
    /// Transverse radius of curvature R \[m\].
    pub radius: f64,
    /// Subtended angle alpha \[rad\].
    pub alpha: f64,
}

impl TapeGeometry {
    /// Checks that every dimension is positive and `alpha < 2 pi`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad value.
    pub fn validate(&self) -> Result<()> {
        check_positive("tape length L [m]", self.length)?;
        check_positive("tape radius R [m]", self.radius)?;
        check_positive("subtended angle alpha [rad]", self.alpha)?;
        if self.alpha >= 2.0 * std::f64::consts::PI {
            return Err(Error::InvalidParameter(format!(
                "subtended angle alpha must be < 2 pi (got {} rad)",
                shown(self.alpha)
            )));
        }
        Ok(())
    }

    /// Point of the mid-surface at abscissa `x` and arc angle `phi` (0 on the symmetry plane).
    #[must_use]
    pub fn point(&self, x: f64, phi: f64) -> Vector3<f64> {
        Vector3::new(x, self.radius * phi.sin(), self.radius * (1.0 - phi.cos()))
    }

    /// Centroid of the cross-section arc, relative to the arc's middle point: `(0, 0, z_c)` with
    /// `z_c = R (1 - sin(alpha/2) / (alpha/2))` \[m\].
    #[must_use]
    pub fn section_centroid_z(&self) -> f64 {
        let h = 0.5 * self.alpha;
        self.radius * (1.0 - h.sin() / h)
    }
}

/// Most elements [`tape_spring`] generates: a guard against a mesh size that would exhaust memory
/// or wrap the counts (the set-up and bending scenarios refuse far fewer, a million per tape).
pub const MAX_GENERATED_ELEMENTS: f64 = 2e7;

/// Elements along and across a tape spring that [`tape_spring`] makes at the size `h` \[m\]:
/// the length and the arc over `h`, rounded half away from zero, at least 1 along and 2 across,
/// the count across made even. The one home of that rule (the set-up's scenarios ask it how many
/// elements span the section before they build anything).
///
/// # Errors
/// [`Error::InvalidParameter`] for a bad geometry or size, or more than
/// [`MAX_GENERATED_ELEMENTS`].
pub fn tape_spring_divisions(geometry: &TapeGeometry, h: f64) -> Result<(usize, usize)> {
    geometry.validate()?;
    check_positive("mesh size h [m]", h)?;
    // Counted in floating point first: an absurd ratio must be refused, not wrapped by the cast.
    let nx_f = (geometry.length / h).round().max(1.0);
    let na_f = (geometry.radius * geometry.alpha / h).round().max(2.0);
    if nx_f * na_f > MAX_GENERATED_ELEMENTS {
        return Err(Error::InvalidParameter(format!(
            "mesh size h = {} m gives {} x {} elements, more than the {} this generator makes: use a larger h",
            shown(h),
            shown(nx_f),
            shown(na_f),
            shown(MAX_GENERATED_ELEMENTS)
        )));
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (nx, na) = (nx_f as usize, na_f as usize);
    Ok((nx, na + na % 2))
}

/// Tape-spring mesh with elements of size about `h` \[m\] (the arc count is rounded up to an even
/// number so that a line of nodes lies on the symmetry plane).
///
/// Node sets: `end0` (x = 0), `end1` (x = L), `side0`, `side1` (the free edges), `midline`
/// (symmetry line y = 0), `all`.
///
/// # Errors
/// [`Error::InvalidParameter`] for a bad geometry or element size.
pub fn tape_spring(geometry: &TapeGeometry, h: f64) -> Result<Mesh> {
    let (nx, na) = tape_spring_divisions(geometry, h)?;
    let g = *geometry;
    let mut mesh = grid(nx, na, |s, r| g.point(s * g.length, (r - 0.5) * g.alpha))?;
    rename(
        &mut mesh,
        &[("s0", "end0"), ("s1", "end1"), ("r0", "side0"), ("r1", "side1")],
    );
    let mid = na / 2;
    mesh.add_node_set("midline", (0..=nx).map(|i| mid * (nx + 1) + i).collect())?;
    Ok(mesh)
}

/// Twists the sections of a tape spring about the x axis by `amplitude * sin(pi x / L)` \[rad\], a
/// geometric imperfection that selects one branch at the equal-sense bifurcation.
pub fn apply_twist_imperfection(mesh: &mut Mesh, length: f64, amplitude: f64) {
    for x in &mut mesh.nodes {
        let angle = amplitude * (std::f64::consts::PI * x.x / length).sin();
        let (s, c) = angle.sin_cos();
        let (y, z) = (x.y, x.z);
        x.y = c * y - s * z;
        x.z = s * y + c * z;
    }
}

fn rename(mesh: &mut Mesh, pairs: &[(&str, &str)]) {
    for (from, to) in pairs {
        if let Some(set) = mesh.node_sets.remove(*from) {
            mesh.node_sets.insert((*to).to_owned(), set);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 0 to 7 rad gave a panel lying on itself, -1e300 to 1e300 rad nodes at sin() of round-off;
    /// one full turn, and a half radian near the largest angle, are meshes.
    #[test]
    fn a_panel_is_at_most_one_turn_of_angles_that_keep_their_digits() {
        let refused = |phi0: f64, phi1: f64| match cylindrical_panel(0.1, 0.2, phi0, phi1, 2, 4) {
            Err(Error::InvalidParameter(m)) => m,
            other => panic!("{phi0} to {phi1}: {other:?}"),
        };
        assert!(refused(0.0, 7.0).contains("phi1 - phi0 = 7 rad is more than one turn"));
        assert!(refused(-1e300, 1e300).contains("phi0 = -1e300 rad is beyond 1e6 rad"));
        assert!(refused(0.0, 2e6).contains("phi1 = 2000000 rad is beyond"));
        assert!(refused(f64::NAN, 1.0).contains("angular span"));
        let turn = cylindrical_panel(0.1, 0.2, 0.0, 2.0 * std::f64::consts::PI, 2, 8).expect("one turn");
        assert_eq!(turn.quads.len(), 16);
        let far = cylindrical_panel(0.1, 0.2, -MAX_PANEL_ANGLE, -MAX_PANEL_ANGLE + 0.5, 1, 1).expect("far");
        for x in &far.nodes {
            assert!((x.y.hypot(x.z) - 0.1).abs() < 1e-12 * 0.1);
        }
    }

    #[test]
    fn tape_spring_section_is_the_requested_arc() {
        let g = TapeGeometry {
            length: 0.1,
            radius: 15.55e-3,
            alpha: 69.85_f64.to_radians(),
        };
        let mesh = tape_spring(&g, 2e-3).unwrap();
        assert_eq!(mesh.quads.len(), 50 * 10);
        let centre = Vector3::new(0.0, 0.0, g.radius);
        for &n in mesh.node_set("end1").unwrap() {
            let x = mesh.nodes[n];
            assert!((x.x - 0.1).abs() < 1e-15);
            assert!(((x - Vector3::new(x.x, 0.0, 0.0) - centre).norm() - g.radius).abs() < 1e-12);
        }
        let side = mesh.nodes[mesh.node_set("side1").unwrap()[0]];
        assert!((side.y.atan2(g.radius - side.z) - g.alpha / 2.0).abs() < 1e-12);
    }

    #[test]
    fn divisions_round_half_away_and_make_the_arc_even() {
        // The paper's tape, arc 18.96 mm: 2.5 arc widths round to 3, made 4; 5.5 to 6.
        let g = TapeGeometry {
            length: 0.1,
            radius: 15.55e-3,
            alpha: 69.85_f64.to_radians(),
        };
        let arc = g.radius * g.alpha;
        assert_eq!(tape_spring_divisions(&g, arc / 2.5).unwrap().1, 4);
        assert_eq!(tape_spring_divisions(&g, arc / 2.49).unwrap().1, 2);
        assert_eq!(tape_spring_divisions(&g, arc / 5.5).unwrap().1, 6);
        assert_eq!(tape_spring_divisions(&g, 1.0).unwrap(), (1, 2));
        for h in [1e-3, 2e-3, 3.3e-3, 7.58e-3, 0.05] {
            let (along, across) = tape_spring_divisions(&g, h).unwrap();
            assert_eq!(tape_spring(&g, h).unwrap().quads.len(), along * across, "h = {h}");
        }
    }

    #[test]
    fn an_absurd_tape_is_refused_with_short_numbers() {
        let long = TapeGeometry {
            length: 1e300,
            radius: 15.55e-3,
            alpha: 1.2,
        };
        let message = tape_spring(&long, 2e-3).unwrap_err().to_string();
        assert!(message.contains("gives 5e302 x 9 elements"), "{message}");
        assert!(message.len() < 200, "{message}");
        let wide = TapeGeometry { alpha: 1e300, ..long };
        let message = wide.validate().unwrap_err().to_string();
        assert!(message.contains("(got 1e300 rad)"), "{message}");
    }
}

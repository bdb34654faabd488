//! Static equilibrium paths: `r(q, t) = f_int(q) - f_ext(t) = 0` at the free DOFs, with the
//! constrained DOFs moving as their time functions say; in static steps the load factor `lambda`
//! plays the role of time `t`.
//!
//! Every increment is a bordered Newton iteration: with `K = dr/dq` and
//! `b = -dr/dlambda = df_ext/dt - K_fc * rates`, each iteration solves `K dq_r = -r` and
//! `K dq_b = b` (one factorisation, two solves) and sets `dq = dq_r + dlambda dq_b`, where `dlambda`
//! comes from the control equation: zero (load control), the controlled DOF fixed (displacement
//! control, Batoz & Dhatt 1979), or the arc-length constraint `|Dq|_W^2 + Dlambda^2 c = Ds^2`
//! (Crisfield 1981), whose root is chosen at the smallest angle with the predictor; where it has
//! no real root, the correction takes the quadratic's closest approach twice, then keeps to the
//! plane normal to the increment so far (Ramm 1981), which a correction from a nearly singular
//! tangent always cuts, where cutting the increment back only crept towards the singular point.
//! A load-control increment's predictor solves with the loads' and motions' secant over the
//! increment instead of `b`, so that a time function far steeper than the increment (a ramp over
//! a microsecond) adds what it adds, not its slope times the increment. The first
//! predictor follows the tangent in the requested direction; later ones follow the tangent at the
//! converged state (when its factorisation is at hand from the stability count) oriented like the
//! previous increment (Feng et al. 1996), or else, and always after a cut-back, extrapolate the
//! previous converged increment (secant predictor). A converged increment that turns back on the
//! path (negative inner product with the previous one) is rejected and cut back, and one that bends
//! by more than 60 degrees is refined, so limit points, snap-through and snap-back are passed
//! without reversing or jumping branches. Norms weigh rotations by the characteristic length `L_c`
//! of the model.
//!
//! The driver is a loop of *propose* (the next increment from the [`StepController`]), *attempt*
//! (the Newton iteration), then *accept* (record the state, adapt the increment) or *reject* (restore
//! the last converged state, halve the increment). An increment is rejected for the reasons of
//! `Rejection`; after `max_cutbacks` successive halvings, or once the increment is below
//! round-off, the analysis stops with [`Error::NotConverged`] and the path so far.
//!
//! On an arc-length path, limit points of the load factor and extrema of a monitored reaction
//! can be located (see [`super::StaticParams`]): once a converged step shows the path turned
//! (the load factor, or the monitored reaction, changed its sense of variation), the extremum is
//! searched for between the last three converged states by solving for equilibria on hyperplanes
//! across the chord of that stretch (`(z - z_a) . c = s |c|^2`, `z = (q, lambda)`, a linear
//! constraint in the bordered system), with a parabolic search in `s`, and recorded at its place in
//! path order. The path itself (its converged steps) is unchanged by this: the located states are
//! inserted, and the solver resumes from the state it had reached.

use std::time::Instant;

use super::control::{GiveUp, StepController};
use super::events::{
    after_step, before_jump, first_plane, zero_ahead, zero_to_stop_at, Found, Point, ZeroSearch, ZeroWatch,
};
use super::newton::{Convergence, Stall};
use super::retrace::PathMemory;
use super::{Control, Event, Rejection, StaticParams, StaticPath, StaticStep, Stats, ZeroStop};

/// Largest condition number of the tangent, as the load's response shows it, under load
/// control (see `Driver::load_carried`): above it fewer than 4 significant digits are left.
/// Measured: at most 3e8 over every load-controlled increment of the test suite; 7e15 to 9e16
/// (round-off pivots) for plates of 0.2 to 20 m turning about two pinned points.
const SINGULAR_CONDITION: f64 = 1e12;

/// Largest share of the loads by which a state accepted at the residual's round-off floor may
/// miss equilibrium (see `Driver::unresolved`): beyond it the loads are below what the model's
/// forces resolve in floating point, and the state is noise. Measured: a 10 m thick steel plate
/// (0.2 x 0.02 m) under 1 mN was accepted 79 % out of equilibrium (its floor 1.8e-3 N). Over
/// the Rust and Python test suites the floor accepted 560 loaded states, missing equilibrium by
/// at most 5.2e-6 of the loads, and by 1.4e-4 in one of the model's property tests (a section
/// value drawn over 600 orders of magnitude, under 1 mN).
const RESOLUTION: f64 = 1e-3;
use crate::assembly::{Assembled, System};
use crate::constraint::Slot;
use crate::element::shell::ElementStress;
use crate::error::{Clock, Error, Result};
use crate::state::State;

/// What one increment does.
#[derive(Clone, Debug)]
pub(super) enum Increment {
    Load(f64),
    Displacement {
        eq: usize,
        delta: f64,
    },
    Arc {
        ds: f64,
        direction: f64,
    },
    /// Equilibrium on the hyperplane through `z_start + fraction c` normal to the chord
    /// `c = (chord, chord_lambda)` (in the arc-length metric): predictor `fraction c`, then
    /// corrections orthogonal to `c` (Riks' normal plane).
    Plane {
        chord: Vec<f64>,
        chord_lambda: f64,
        fraction: f64,
    },
}

pub(super) struct Outcome {
    pub iterations: usize,
    pub residual: f64,
    pub dq: Vec<f64>,
    pub dlambda: f64,
}

pub(super) struct Driver<'a> {
    pub system: &'a mut System,
    pub asm: Assembled,
    /// Static residual `f_int - f_ext` of `asm`.
    pub r: Vec<f64>,
    /// `asm` holds the pieces and tangent of the current state.
    pub fresh: bool,
    /// `system.linear` holds the factorisation of `asm`'s tangent.
    pub factorised: bool,
    /// Element stresses of the mixed iteration at the current state (linearised from the last
    /// iterate), used by the next tangent when `stress_valid`.
    pub stress: Vec<ElementStress>,
    pub stress_valid: bool,
    pub conv: Convergence,
    force_floor: f64,
    /// Reject arc-length steps that bend sharply (cleared after repeated cut-backs).
    strict_turns: bool,
    /// Use the tangent predictor when a factorisation of the converged state is at hand (off
    /// after a cut-back: the secant predictor is safer at sharp turns).
    tangent_predictor: bool,
    /// Increment of the last converged step, for the arc-length secant predictor.
    pub previous: Option<(Vec<f64>, f64)>,
    /// Fraction of the standard push along a critical mode that the last trial push which
    /// relaxed used (1 until a shorter one was needed, see `Driver::pushed_relaxed`).
    pub push_factor: f64,
    pub weights: Vec<f64>,
    /// Rates of the constrained DOFs, `value f'(t)`, at the current state.
    rates: Vec<f64>,
    /// Weight of the load factor in the arc-length norm: `|rates|_W^2`.
    c_lambda: f64,
    pub params: &'a StaticParams,
    pub stats: Stats,
}

impl Driver<'_> {
    pub fn assemble(&mut self, state: &State) {
        let t = Instant::now();
        let stress = self.stress_valid.then_some(self.stress.as_slice());
        self.system
            .assemble_mixed(state, true, stress, &mut self.asm);
        self.asm.residual_into(&mut self.r);
        self.rates = self.system.constrained_rates(state.t);
        self.stats.assembly_s += t.elapsed().as_secs_f64();
        self.fresh = true;
        self.factorised = false;
    }

    /// Moves `state` by `(dq, dlambda)`; in the mixed iteration the element stresses follow the
    /// linearised kinematics of that move.
    fn advance(&mut self, state: &mut State, dq: &[f64], dlambda: f64) {
        let dc = self.system.constrained_increments(state.t, dlambda);
        if self.params.newton.mixed_stress {
            let t = Instant::now();
            self.system
                .linearised_stresses(state, dq, &dc, &mut self.stress);
            self.stats.assembly_s += t.elapsed().as_secs_f64();
            self.stress_valid = true;
        }
        self.system.update_with(state, dq, &dc);
        state.t += dlambda;
    }

    /// Rejects load control on a tangent that is singular along the load: the response `dq_b` to
    /// the load `q` implies a condition number of the tangent above [`SINGULAR_CONDITION`],
    /// `|dq_b| |K| / |q|` (largest entries, rotations times the characteristic length and moments
    /// over it, so that all are metres and newtons). That is a mechanism the load drives (its
    /// pivot is round-off: faer's supernodal LDL^T does not report it as zero), or a limit point
    /// hit to within round-off; either way the increment's Newton iteration would carry the
    /// structure to an arbitrary remote equilibrium (a plate turning about two pinned points
    /// jumped to its unstable hanging position). The measure does not depend on the load's size
    /// or the model's. Rejected at every size, the increment is cut back to round-off and the
    /// step reports it. Displacement and arc-length control pass limit points by design and are
    /// not checked.
    fn load_carried(&self, dq_b: &[f64]) -> std::result::Result<(), Rejection> {
        let dofs = &self.system.dofs.free_dofs;
        // The arc-length metric's lengths: 1 for translations, L_c for rotations.
        let scale: Vec<f64> = self.weights.iter().map(|w| w.sqrt()).collect();
        let p = &self.system.pattern_ff;
        let mut k_max: f64 = 0.0;
        for j in 0..p.nrows {
            for e in p.col_ptr[j]..p.col_ptr[j + 1] {
                k_max = k_max.max(self.asm.k_ff[e].abs() / (scale[p.row_idx[e]] * scale[j]));
            }
        }
        let q = self.load_vector();
        let q_max = q
            .iter()
            .zip(&scale)
            .fold(0.0_f64, |m, (v, s)| m.max(v.abs() / s));
        let (i_max, x_max) = dq_b
            .iter()
            .zip(&scale)
            .map(|(v, s)| v.abs() * s)
            .enumerate()
            .fold(
                (0, 0.0_f64),
                |(im, m), (i, x)| if x > m || x.is_nan() { (i, x) } else { (im, m) },
            );
        let condition = x_max * k_max / q_max;
        if condition > SINGULAR_CONDITION || x_max.is_nan() {
            let (node, dof) = dofs[i_max];
            let unit = if dof.is_rotation() { "rad" } else { "m" };
            return Err(Rejection::Singular(format!(
                "the tangent is singular along the load (condition number at least {condition:.1e}): \
                 {} of node {node} responds by {:.3e} {unit} per unit load factor (a mechanism \
                 the load drives?)",
                dof.name(),
                dq_b[i_max].abs()
            )));
        }
        Ok(())
    }

    /// Forgets everything computed at the current state (after it was replaced).
    pub fn invalidate(&mut self) {
        self.fresh = false;
        self.factorised = false;
        self.stress_valid = false;
    }

    pub fn dot_w(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.weights)
            .map(|((x, y), w)| w * x * y)
            .sum()
    }

    pub fn force_norm(&self, f: &[f64]) -> f64 {
        System::force_norm(f, &self.weights)
    }

    fn reaction_norm(&self) -> f64 {
        let lc2 = self.system.char_length.powi(2);
        self.system
            .dofs
            .constrained
            .iter()
            .zip(self.asm.f_int_c.iter().zip(&self.asm.f_ext_c))
            .map(|(c, (i, e))| {
                let r = i - e;
                if c.dof.is_rotation() {
                    r * r / lc2
                } else {
                    r * r
                }
            })
            .sum::<f64>()
            .sqrt()
    }

    /// The error for a state accepted with `residual` only because the residual's round-off
    /// floor is above the force tolerance, when that residual is more than [`RESOLUTION`] of the
    /// largest load norm `max_load` of the path so far: the loads are then below what the model
    /// resolves (a stiff section under a tiny load, or a unit slip), and the displacements they
    /// give are round-off. Raised for the step's last state only (`Walk::finish`). Nothing is
    /// checked without loads (a prescribed motion, a rigid turn: the reactions are the forces
    /// then, and a zero reaction is no error).
    fn unresolved(&self, residual: f64, max_load: f64, lambda: f64, iterations: usize) -> Option<Error> {
        let floor_only = residual > self.conv.tol_force * self.reference_force();
        (max_load > 0.0 && floor_only && residual > RESOLUTION * max_load).then(|| Error::NotConverged {
            step: None,
            t: lambda,
            clock: Clock::LoadFactor,
            iterations,
            residual,
            detail: format!(
                "the loads ({max_load:.3e} N at most) are below the model's force resolution: its \
                 internal forces cancel in floating point only to about {:.3e} N (the residual's \
                 round-off floor, from Young's modulus, thickness, size and mesh), and the step's \
                 last state misses equilibrium by {residual:.3e} N, more than {RESOLUTION:e} of \
                 the loads; raise the loads or check the section's units",
                self.conv.round_off
            ),
        })
    }

    pub fn reference_force(&self) -> f64 {
        self.force_norm(&self.asm.f_ext)
            .max(self.reaction_norm())
            .max(self.force_floor)
    }

    /// `b = df_ext/dt - K_fc rates`.
    fn load_vector(&self) -> Vec<f64> {
        let mut b = self.asm.df_ext.clone();
        let mut kv = vec![0.0; b.len()];
        self.system
            .pattern_fc
            .mul_add(&self.asm.k_fc, &self.rates, &mut kv);
        for (bi, k) in b.iter_mut().zip(kv) {
            *bi -= k;
        }
        b
    }

    /// The response `K^-1 b_s` to the load's secant over the load-control increment `dl`,
    /// `b_s = (f_ext(t + dl) - f_ext(t) - K_fc (c(t + dl) - c(t))) / dl`, where `dq_b` is the
    /// response to its slope at `t`, [`Self::load_vector`]. The two are the same for linear and
    /// constant time functions (no second solve then); where a ramp ends or a table turns within
    /// the increment the slope would extrapolate the load (a ramp over a microsecond: a million
    /// times it over a unit increment) and the predictor would start Newton out of reach.
    fn secant_response(&mut self, state: &State, dl: f64, dq_b: Vec<f64>) -> Result<Vec<f64>> {
        let mut b = self.system.load_secant(state, dl);
        let dc: Vec<f64> = self
            .system
            .constrained_increments(state.t, dl)
            .iter()
            .map(|c| c / dl)
            .collect();
        let mut kv = vec![0.0; b.len()];
        self.system.pattern_fc.mul_add(&self.asm.k_fc, &dc, &mut kv);
        for (bi, k) in b.iter_mut().zip(kv) {
            *bi -= k;
        }
        if b == self.load_vector() {
            return Ok(dq_b);
        }
        let t = Instant::now();
        self.system.linear.solve_in_place(&mut b)?;
        self.stats.solve_s += t.elapsed().as_secs_f64();
        Ok(b)
    }

    /// Factorises the current tangent (if not done yet).
    pub fn factorise(&mut self) -> Result<()> {
        if !self.factorised {
            let t = Instant::now();
            self.system.linear.factorize(&self.asm.k_ff)?;
            self.stats.factorisations += 1;
            self.factorised = true;
            let dt = t.elapsed().as_secs_f64();
            self.stats.solve_s += dt;
            self.stats.factorisation_s += dt;
        }
        Ok(())
    }

    /// Factorises the current tangent and returns `(dq_r, dq_b)`.
    pub fn solve_pair(&mut self) -> Result<(Vec<f64>, Vec<f64>)> {
        self.factorise()?;
        let t = Instant::now();
        let mut dq_r: Vec<f64> = self.r.iter().map(|r| -r).collect();
        self.system.linear.solve_in_place(&mut dq_r)?;
        let mut dq_b = self.load_vector();
        self.system.linear.solve_in_place(&mut dq_b)?;
        self.stats.solve_s += t.elapsed().as_secs_f64();
        Ok((dq_r, dq_b))
    }

    pub fn converged(&self, energy: Option<(f64, f64)>) -> (bool, f64) {
        let res = self.force_norm(&self.r);
        (self.conv.test(res, self.reference_force(), energy), res)
    }

    /// Norm of an increment in the arc-length metric.
    pub fn arc_norm(&self, dq: &[f64], dlambda: f64) -> f64 {
        (self.dot_w(dq, dq) + dlambda * dlambda * self.c_lambda).sqrt()
    }

    /// Inner product of two increments in the arc-length metric.
    pub fn arc_dot(&self, a: (&[f64], f64), b: (&[f64], f64)) -> f64 {
        self.dot_w(a.0, b.0) + a.1 * b.1 * self.c_lambda
    }

    /// The load factor's correction `dl` that keeps the increment `acc` plus the correction
    /// `dq_r + dl dq_b` on the plane orthogonal to `chord` through `fraction` of it:
    /// `(acc - fraction c + dq_r + dl dq_b) . c = 0` (arc-length norm, load factor included).
    fn plane_correction(
        &self,
        acc: (&[f64], f64),
        dq_r: &[f64],
        dq_b: &[f64],
        chord: (&[f64], f64),
        fraction: f64,
    ) -> std::result::Result<f64, Rejection> {
        let num = fraction * self.arc_dot(chord, chord) - self.arc_dot(acc, chord) - self.dot_w(dq_r, chord.0);
        let den = self.arc_dot((dq_b, 1.0), chord);
        if den.abs() < 1e-300 {
            return Err(Rejection::NoArcRoot);
        }
        Ok(num / den)
    }

    /// One increment from the converged `state`; on rejection the state is left modified.
    #[allow(clippy::too_many_lines)]
    pub fn increment(&mut self, state: &mut State, inc: &Increment) -> std::result::Result<Outcome, Rejection> {
        // The plane's predictor needs nothing of the start state.
        if !self.fresh && !matches!(inc, Increment::Plane { .. }) {
            self.assemble(state);
        }
        let tangent_predictor = self.factorised && self.tangent_predictor;
        let (dlambda0, dq) = match (inc, &self.previous) {
            (Increment::Arc { ds, .. }, Some((prev_dq, prev_dl))) if tangent_predictor => {
                // Tangent predictor from the factorisation already made for the stability count,
                // oriented like the previous increment (Feng et al. 1996).
                let mut dq_b = self.load_vector();
                self.system.linear.solve_in_place(&mut dq_b)?;
                let sign = if self.dot_w(prev_dq, &dq_b) + prev_dl * self.c_lambda >= 0.0 {
                    1.0
                } else {
                    -1.0
                };
                let norm = (self.dot_w(&dq_b, &dq_b) + self.c_lambda).sqrt();
                let dl = sign * ds / norm;
                (dl, dq_b.iter().map(|v| dl * v).collect())
            }
            (Increment::Arc { ds, .. }, Some((prev_dq, prev_dl))) => {
                // Secant predictor: extrapolate the last converged increment to the new arc length.
                let norm = (self.dot_w(prev_dq, prev_dq) + prev_dl * prev_dl * self.c_lambda).sqrt();
                let scale = ds / norm;
                (scale * prev_dl, prev_dq.iter().map(|v| scale * v).collect())
            }
            (
                Increment::Plane {
                    chord,
                    chord_lambda,
                    fraction,
                },
                _,
            ) => (fraction * chord_lambda, chord.iter().map(|c| fraction * c).collect()),
            _ => {
                let (dq_r, dq_b) = self.solve_pair()?;
                // (load factor increment, correction at the fixed load, the load's response)
                let (dlambda0, mut dq, direction) = match inc {
                    Increment::Load(dl) => {
                        self.load_carried(&dq_b)?;
                        (*dl, dq_r, self.secant_response(state, *dl, dq_b)?)
                    }
                    Increment::Displacement { eq, delta } => {
                        if dq_b[*eq].abs() < 1e-300 {
                            return Err(Rejection::NoResponse);
                        }
                        ((delta - dq_r[*eq]) / dq_b[*eq], dq_r, dq_b)
                    }
                    Increment::Arc { ds, direction } => {
                        let norm = (self.dot_w(&dq_b, &dq_b) + self.c_lambda).sqrt();
                        (direction * ds / norm, vec![0.0; dq_b.len()], dq_b)
                    }
                    Increment::Plane { .. } => unreachable!("handled above"),
                };
                for (d, b) in dq.iter_mut().zip(&direction) {
                    *d += dlambda0 * b;
                }
                (dlambda0, dq)
            }
        };
        self.advance(state, &dq, dlambda0);
        let mut acc = dq;
        let mut acc_lambda = dlambda0;
        let mut energy_first = None;
        let max_it = self.params.newton.max_iterations;
        let mut res = f64::INFINITY;
        let mut no_root = 0;
        // An iteration that has not improved on its best residual for `stall_iterations`
        // iterations is cycling, not converging, and is cut back at once rather than after
        // `max_iterations`.
        let mut stall = Stall::new(self.params.newton.stall_iterations);
        let mut stalled = false;
        let mut last_it = max_it;
        for it in 1..=max_it {
            self.stats.iterations += 1;
            self.assemble(state);
            let (ok, r) = self.converged(energy_first);
            res = r;
            log::trace!("t = {:.6e}: Newton iteration {it}, residual {res:.3e}", state.t);
            if !res.is_finite() {
                return Err(Rejection::NonFinite);
            }
            if ok {
                return self.checked(inc, it, res, acc, acc_lambda);
            }
            if stall.stalled(it, res) {
                stalled = true;
                last_it = it;
                break;
            }
            if it == max_it {
                break;
            }
            let (dq_r, dq_b) = self.solve_pair()?;
            let dl = match inc {
                Increment::Load(_) => 0.0,
                Increment::Displacement { eq, .. } => -dq_r[*eq] / dq_b[*eq],
                Increment::Arc { ds, .. } => {
                    let u: Vec<f64> = acc.iter().zip(&dq_r).map(|(a, r)| a + r).collect();
                    let a = self.dot_w(&dq_b, &dq_b) + self.c_lambda;
                    let b = 2.0 * (self.dot_w(&dq_b, &u) + acc_lambda * self.c_lambda);
                    let c = self.dot_w(&u, &u) + acc_lambda * acc_lambda * self.c_lambda - ds * ds;
                    let disc = b * b - 4.0 * a * c;
                    if disc < 0.0 {
                        no_root += 1;
                        if no_root <= 2 {
                            -b / (2.0 * a)
                        } else {
                            // The sphere is out of reach from here (a nearly singular tangent,
                            // whose corrections are long in its null direction, beside a
                            // bifurcation the path passes): the plane normal to the increment so
                            // far, at its own end, always cuts the correction's line unless it is
                            // parallel to it. Cutting the increment back only crept towards the
                            // singular point, the increments shrinking to nothing.
                            self.plane_correction((&acc, acc_lambda), &dq_r, &dq_b, (&acc, acc_lambda), 1.0)?
                        }
                    } else {
                        let sq = disc.sqrt();
                        let roots = [(-b + sq) / (2.0 * a), (-b - sq) / (2.0 * a)];
                        let score = |l: f64| {
                            let new: Vec<f64> = u.iter().zip(&dq_b).map(|(x, y)| x + l * y).collect();
                            self.dot_w(&new, &acc) + (acc_lambda + l) * acc_lambda * self.c_lambda
                        };
                        if score(roots[0]) >= score(roots[1]) {
                            roots[0]
                        } else {
                            roots[1]
                        }
                    }
                }
                Increment::Plane {
                    chord,
                    chord_lambda,
                    fraction,
                } => self.plane_correction((&acc, acc_lambda), &dq_r, &dq_b, (chord, *chord_lambda), *fraction)?,
            };
            let step: Vec<f64> = dq_r.iter().zip(&dq_b).map(|(r, b)| r + dl * b).collect();
            let e = self
                .r
                .iter()
                .zip(&step)
                .map(|(r, s)| r * s)
                .sum::<f64>()
                .abs();
            let energy = match energy_first {
                None => Some((e.max(1e-300), e)),
                Some((first, _)) => Some((first, e)),
            };
            energy_first = energy;
            // Converged in force, and the correction just computed is negligible in energy: accept
            // the current state (its tangent is factorised, ready for the stability check and the
            // next predictor) instead of paying an assembly to confirm what the energy says.
            if let Some((first, last)) = energy {
                if it > 1 && last <= self.params.newton.tol_energy * first && self.converged(None).0 {
                    return self.checked(inc, it, res, acc, acc_lambda);
                }
            }
            let line_search = matches!(inc, Increment::Load(_) | Increment::Displacement { .. });
            let mut alpha = 1.0;
            let saved = (line_search && self.params.newton.line_search).then(|| state.clone());
            loop {
                let scaled: Vec<f64> = step.iter().map(|s| alpha * s).collect();
                self.advance(state, &scaled, alpha * dl);
                let Some(saved) = &saved else { break };
                if alpha < 0.1 {
                    break;
                }
                let t = Instant::now();
                self.system.assemble(state, false, &mut self.asm);
                self.asm.residual_into(&mut self.r);
                self.stats.assembly_s += t.elapsed().as_secs_f64();
                self.fresh = false;
                let new_res = self.force_norm(&self.r);
                if new_res.is_finite() && new_res <= res {
                    break;
                }
                *state = saved.clone();
                alpha *= 0.5;
            }
            for (a, s) in acc.iter_mut().zip(&step) {
                *a += alpha * s;
            }
            acc_lambda += alpha * dl;
        }
        Err(Rejection::NotConverged {
            iterations: last_it,
            residual: res,
            stalled,
        })
    }

    /// A converged increment: rejected if it turned back or bent sharply on the arc-length path.
    fn checked(
        &self,
        inc: &Increment,
        iterations: usize,
        residual: f64,
        dq: Vec<f64>,
        dlambda: f64,
    ) -> std::result::Result<Outcome, Rejection> {
        if let (Increment::Arc { .. }, Some((prev_dq, prev_dl))) = (inc, &self.previous) {
            // A converged increment that turns back on the path means the step jumped
            // across a sharp turn: reject it so that the step is cut back.
            let dot = self.dot_w(&dq, prev_dq) + dlambda * prev_dl * self.c_lambda;
            let norms = ((self.dot_w(&dq, &dq) + dlambda * dlambda * self.c_lambda)
                * (self.dot_w(prev_dq, prev_dq) + prev_dl * prev_dl * self.c_lambda))
                .sqrt();
            if dot <= 0.0 {
                return Err(Rejection::TurnedBack);
            }
            // A bend of more than 60 degrees in one step may have jumped to another branch (seen on a
            // 4 mm tape unloading past the heel): refine (the driver accepts it once half of the
            // cut-backs are spent).
            if dot < 0.5 * norms && self.strict_turns {
                return Err(Rejection::BentSharply);
            }
        }
        Ok(Outcome {
            iterations,
            residual,
            dq,
            dlambda,
        })
    }

    /// The converged `state` as a recorded step (stability count if asked).
    pub fn record(&mut self, state: &State, out: &Outcome) -> Result<StaticStep> {
        let negative_eigenvalues = if self.params.stability {
            // The LDL^T of the converged tangent is the one factorised for the convergence check.
            self.factorise()?;
            let t = Instant::now();
            let n = self.system.linear.negative_eigenvalues()?;
            self.stats.solve_s += t.elapsed().as_secs_f64();
            Some(n)
        } else {
            None
        };
        let (displacements, rotations) = if self.params.record_fields {
            self.system.fields(state)
        } else {
            (Vec::new(), Vec::new())
        };
        let markers = self
            .system
            .marker_positions(state)
            .iter()
            .map(|x| (*x).into())
            .collect();
        let marker_rotations = self
            .system
            .marker_rotations(state)
            .iter()
            .map(|x| (*x).into())
            .collect();
        let probes = self.system.probe(&self.asm);
        Ok(StaticStep {
            lambda: state.t,
            iterations: out.iterations,
            residual: out.residual,
            energy: self.asm.energy,
            gravity_energy: self.asm.gravity_energy,
            reactions: self.asm.reactions(),
            negative_eigenvalues,
            displacements,
            rotations,
            markers,
            marker_rotations,
            probes,
            jump: false,
            event: None,
            arc: 0.0,
            ..StaticStep::default()
        })
    }

    /// Weighted distance between two configurations (translations \[m\], rotations times `L_c`).
    pub fn distance(&self, a: &State, b: &State) -> f64 {
        let lc2 = self.system.char_length.powi(2);
        a.x.iter()
            .zip(&b.x)
            .zip(a.q.iter().zip(&b.q))
            .map(|((xa, xb), (qa, qb))| {
                (xa - xb).norm_squared() + lc2 * (qa * qb.inverse()).scaled_axis().norm_squared()
            })
            .sum::<f64>()
            .sqrt()
    }

    /// Index of the reaction of `monitor` among the constrained DOFs.
    pub fn monitor_index(&self) -> Option<usize> {
        let m = self.params.monitor?;
        self.system
            .dofs
            .constrained
            .iter()
            .position(|c| c.node == m.node && c.dof == m.dof)
    }
}

/// A step from a stable state onto an unstable one is retried shorter until it is at most the
/// first arc-length step over this, before the instability is taken for a bifurcation.
const CLOSE_IN: f64 = 16.0;

/// Accepted steps that each move the load factor by less than this fraction of the first step's
/// are crawling (see `Walk::crawling`), once there are [`CRAWL_STEPS`] in a row.
const CRAWL: f64 = 1e-3;
/// See [`CRAWL`].
const CRAWL_STEPS: usize = 5;

/// On the path of a slowly driven test, a step over which the monitored reaction changes by more
/// than this many times `refine_change` is retried shorter (see `Walk::too_coarse`).
const COARSE: f64 = 4.0;

/// After a restart from a relaxed state, the arc length is at most this many times the restarting
/// load increment's, or [`RESTART_FLOOR`] below the path's first arc if longer (see
/// `Walk::accept`); the step control grows it from there.
const RESTART_ARC: f64 = 2.0;
/// See [`RESTART_ARC`]. Measured on the 2 mm equal-sense tape's unloading, twist imperfections
/// 0.08 to 0.12 deg: at the first arc itself, the arc after the jump near -3.18 deg still went
/// round the next branch's limit point (a spurious limit and a spurious jump of about 1 deg, in 7
/// runs of 9); at 1/16 of it, none did (nor at 1/256, in 4 runs). Without a floor, the
/// maximum-mass study's thinnest tape in equal sense crept on at tiny arcs after a jump from a
/// crawling step (its 1000 steps used by 0.18 of the load).
const RESTART_FLOOR: f64 = 16.0;

/// The driver's bookkeeping of one path, between propose, attempt, accept and reject.
struct PathState {
    control: StepController,
    /// Load-factor increment of the last accepted step (None before the first one).
    last_dlambda: Option<f64>,
    /// Steps left (arc-length: `max_steps`).
    steps_left: usize,
    /// Arc length of the first step (arc-length only), once known.
    arc_ds: Option<f64>,
    /// Displacement control: distance travelled.
    travelled: f64,
    /// Arc-length position of the current state from the start of the path.
    arc: f64,
    /// Converged states kept for the location of events and refinement (cleared at jumps).
    history: Vec<Point>,
    /// Negative eigenvalues of the last recorded state (if counted; before the first, 0 if the
    /// path starts with a neutral mode, see `neutral_from_start`).
    last_negative: Option<usize>,
    /// After a jump or a branch switch: the load-factor increment of the restarting step.
    restart: Option<f64>,
    /// Arc-length only: the states followed so far, to stop a path that returns onto itself.
    memory: Option<PathMemory>,
    /// The state of the increment being tried is unstable only by a neutral mode (see
    /// [`Driver::leaves`]): it is recorded without it.
    neutral_reached: bool,
    /// On a path that switches branches: its start and every state since were stable but for one
    /// neutral mode (see `Walk::stable_start`), which each new state is recounted for.
    neutral_from_start: bool,
    /// Steps are being shortened towards an instability found real (see `CLOSE_IN`).
    closing_in: bool,
    /// Largest norm of the external loads at the states recorded so far \[N\].
    max_load: f64,
    /// The error for the last state recorded from Newton if that state is not resolved (see
    /// `Driver::unresolved`): raised if it is the step's last.
    unresolved: Option<Error>,
    /// Load factor and load norm \[N\] of the first state recorded unresolved: named if the
    /// step fails later.
    first_unresolved: Option<(f64, f64)>,
    /// Accepted steps in a row that crawled (see `Walk::crawling`).
    crawl: usize,
    /// The monitored reaction's changes of sign (with `stop_at_monitor_zero`).
    zero: ZeroWatch,
    /// The last state pushed onto the history changed the monitored reaction's sign.
    zero_crossed: bool,
    /// The path stopped at a zero of the monitored reaction (not short of `lambda_end`).
    stopped_at_zero: bool,
}

/// What the driver does after a stage of an increment.
enum Flow {
    /// Propose the next increment.
    Next,
    /// The path ends (completed, failed or cancelled: see the path).
    Stop,
}

/// A state reached by relaxation rather than along the path: a jump past a limit point, a branch
/// switch at a bifurcation, or a relaxation past a neutral mode.
struct Relaxed {
    /// How far from the last recorded state, for the arc position.
    distance: f64,
    /// Reached by a snap.
    jump: bool,
    /// What it marks.
    event: Option<Event>,
}

/// One static path being followed: the driver, its bookkeeping and what is recorded.
struct Walk<'a, 'b> {
    s: Driver<'a>,
    p: PathState,
    path: StaticPath,
    progress: &'b mut dyn FnMut(&StaticStep, &Stats) -> bool,
    lambda_end: Option<f64>,
    arc_control: bool,
    /// Events are located (limit points or extrema of the monitor).
    locate: bool,
    /// Index of the monitored reaction among the constrained DOFs.
    monitor: Option<usize>,
    /// Load-factor scale of round-off.
    scale: f64,
}

/// Follows the static equilibrium path of `system` from `state` as `params` says, calling
/// `progress` after each converged step (return `false` to stop). `state` ends at the last
/// converged configuration.
///
/// Each increment is proposed (`Walk::propose`), attempted (`Driver::increment`), then rejected
/// (`Walk::reject`), or accepted (`Walk::accept`) unless it reaches a limit point to jump from
/// (`Walk::jump_at_limit`), a bifurcation to leave (`Walk::switch_at_bifurcation`), or the final
/// load factor to land on (`Walk::land`).
///
/// # Errors
/// Invalid parameters or a model with nothing to solve are returned at once; failures during the
/// analysis are reported in [`StaticPath::error`] with the converged steps kept.
pub fn solve_static(
    system: &mut System,
    state: &mut State,
    params: &StaticParams,
    progress: &mut dyn FnMut(&StaticStep, &Stats) -> bool,
) -> Result<StaticPath> {
    params.validate()?;
    let start = Instant::now();
    let linear_counts = (system.linear.refinement_sweeps, system.linear.lu_fallbacks);
    let mut w = Walk::new(system, state, params, progress)?;
    while w.p.steps_left > 0 {
        let Some(inc) = w.propose(state)? else { break };
        let saved = state.clone();
        let out = match w.s.increment(state, &inc) {
            Ok(out) => out,
            Err(rejection) => match w.reject(state, saved, &rejection) {
                Flow::Next => continue,
                Flow::Stop => break,
            },
        };
        if w.too_coarse(state, &saved) || w.skipped_instabilities(state, &saved) {
            continue;
        }
        match w.zero_stepped_over(state, &saved, &out) {
            Ok(true) => continue,
            Ok(false) => {}
            Err(e) => {
                *state = saved;
                w.path.error = Some(e);
                break;
            }
        }
        let flow = match w.jump_at_limit(state, &saved) {
            Some(flow) => flow,
            None => match w.switch_at_bifurcation(state, &saved) {
                Some(flow) => flow,
                None => match w.land(state, saved.clone()) {
                    Some(flow) => flow,
                    None => w.accept(state, &saved, out),
                },
            },
        };
        if let Flow::Stop = flow {
            break;
        }
    }
    w.finish(state, start, linear_counts)
}

impl<'a, 'b> Walk<'a, 'b> {
    /// Checks that the model has something to solve, and sets the driver and the step control up.
    #[allow(clippy::too_many_lines)]
    fn new(
        system: &'a mut System,
        state: &State,
        params: &'a StaticParams,
        progress: &'b mut dyn FnMut(&StaticStep, &Stats) -> bool,
    ) -> Result<Self> {
        let arc_control = matches!(params.control, Control::ArcLength { .. });
        let lambda_end = match &params.control {
            Control::Load { lambda_end, .. } | Control::ArcLength { lambda_end, .. } => Some(*lambda_end),
            Control::Displacement { .. } => None,
        };
        system.time_direction = match (lambda_end, &params.control) {
            (Some(end), Control::ArcLength { direction, .. }) if end == state.t => *direction,
            (Some(end), _) if end < state.t => -1.0,
            _ => 1.0,
        };
        let rates = system.constrained_rates(state.t);
        let has_motion = rates.iter().any(|v| *v != 0.0) || system.dofs.constrained.iter().any(|c| c.value != 0.0);
        let has_load = system.loads.iter().any(|l| l.value != 0.0)
            || system
                .gravity
                .as_ref()
                .is_some_and(|(g, _)| *g != nalgebra::Vector3::zeros() && system.total_mass() > 0.0);
        if !has_load && !has_motion {
            return Err(Error::InvalidModel(
                "the analysis has no load and no prescribed motion".into(),
            ));
        }
        if system.dofs.constrained.is_empty() {
            return Err(Error::InvalidModel(
                "the model has no constraint against rigid-body motion".into(),
            ));
        }
        let lc2 = system.char_length.powi(2);
        let c_lambda: f64 = system
            .dofs
            .constrained
            .iter()
            .zip(&rates)
            .map(|(c, v)| if c.dof.is_rotation() { lc2 * v * v } else { v * v })
            .sum();
        let weights = system.free_weights();
        let force_floor = system.force_floor();
        let round_off = system.residual_round_off();
        // Smallest increment worth trying: below it, the increment is lost in the load factor's
        // or the controlled DOF's round-off.
        let scale = state.t.abs().max(lambda_end.map_or(0.0, f64::abs)).max(1.0);
        let (size, steps_left, max_size) = match &params.control {
            Control::Load { lambda_end, increments } => {
                #[allow(clippy::cast_precision_loss)]
                let size = (lambda_end - state.t) / *increments as f64;
                (size, usize::MAX, size.abs())
            }
            Control::Displacement {
                node,
                dof,
                delta,
                increments,
            } => {
                let node = *node;
                if node >= system.dofs.slots.len() {
                    return Err(Error::InvalidModel(format!("controlled node {node} does not exist")));
                }
                if system.dofs.master[node].is_some() {
                    return Err(Error::InvalidModel(format!(
                        "controlled node {node} is rigidly tied; control its reference node"
                    )));
                }
                let Slot::Free(_) = system.dofs.slots[node][dof.index()] else {
                    return Err(Error::InvalidModel(format!(
                        "controlled DOF {} of node {node} is not free",
                        dof.name()
                    )));
                };
                #[allow(clippy::cast_precision_loss)]
                let size = delta / *increments as f64;
                (size, usize::MAX, size.abs())
            }
            Control::ArcLength {
                initial_increment,
                direction,
                max_steps,
                ..
            } => (initial_increment * direction, *max_steps, f64::INFINITY),
        };
        let min_size = match &params.control {
            Control::Displacement { delta, .. } => 1e-14 * delta.abs(),
            _ => 1e-14 * scale,
        };
        let s = Driver {
            system,
            asm: Assembled::default(),
            r: Vec::new(),
            fresh: false,
            factorised: false,
            stress: Vec::new(),
            stress_valid: false,
            conv: Convergence {
                tol_force: params.newton.tol_force,
                tol_energy: params.newton.tol_energy,
                round_off,
            },
            force_floor,
            strict_turns: true,
            tangent_predictor: true,
            previous: None,
            push_factor: 1.0,
            weights,
            rates,
            c_lambda,
            params,
            stats: Stats::default(),
        };
        let monitor = s.monitor_index();
        if let (Some(m), None) = (params.monitor, monitor) {
            return Err(Error::InvalidModel(format!(
                "the monitored reaction ({} of node {}) is not a constrained DOF",
                m.dof.name(),
                m.node
            )));
        }
        let mut w = Self {
            s,
            p: PathState {
                control: StepController::new(size, max_size, min_size, params.target_iterations, params.max_cutbacks),
                last_dlambda: None,
                steps_left,
                arc_ds: None,
                travelled: 0.0,
                arc: 0.0,
                history: Vec::new(),
                last_negative: None,
                restart: None,
                memory: arc_control.then(PathMemory::new),
                neutral_reached: false,
                neutral_from_start: false,
                closing_in: false,
                max_load: 0.0,
                unresolved: None,
                first_unresolved: None,
                crawl: 0,
                zero: ZeroWatch::default(),
                zero_crossed: false,
                stopped_at_zero: false,
            },
            path: StaticPath::default(),
            progress,
            lambda_end,
            arc_control,
            locate: arc_control && (params.locate_limit_points || params.monitor.is_some()),
            monitor,
            scale,
        };
        if let Some(m) = &mut w.p.memory {
            m.restart(state, &w.s.system.reference, None);
        }
        if w.locate {
            // The start of the path is the first point of the location history (the assembly is
            // the one the first increment needs anyway).
            w.s.assemble(state);
            w.push_history(state);
        }
        if let Some(neutral) = w.stable_start(state) {
            w.p.last_negative = Some(0);
            w.p.neutral_from_start = neutral;
        }
        Ok(w)
    }

    /// On a path that switches branches, whether its start `state` is stable (`Some(false)`) or
    /// stable but for one neutral mode (`Some(true)`: a balanced body, a fold free to slide; one
    /// negative pivot, at round-off level by [`Driver::negative_eigenvalues`]); `None` if it is
    /// unstable, not counted, or the path does not switch. A stable start lets the first step be
    /// tested for a bifurcation as every later one is (`last_negative == Some(0)`); with a neutral
    /// mode, the path's states leave it out of their counts, as the states located on the path do
    /// (`events::discount_neutral`) and a state the path restarts from does (`Walk::push_relaxed`),
    /// where every state would count it otherwise. The tangent factorised is the one the first
    /// step needs anyway; a failure here is the first step's to report.
    fn stable_start(&mut self, state: &State) -> Option<bool> {
        if !self.switching() {
            return None;
        }
        if !self.s.fresh {
            self.s.assemble(state);
        }
        let plain = self
            .s
            .factorise()
            .and_then(|()| self.s.system.linear.negative_eigenvalues());
        match plain {
            Ok(0) => Some(false),
            Ok(1) => matches!(self.keeps_neutral(), Ok(true)).then_some(true),
            _ => None,
        }
    }

    /// The next increment; `None` once the path is at its end (or the first arc-length step
    /// could not be sized, an error recorded on the path).
    ///
    /// # Errors
    /// Arc-length control on a model whose loads and motions do not act on the free DOFs.
    fn propose(&mut self, state: &mut State) -> Result<Option<Increment>> {
        let (s, p) = (&mut self.s, &mut self.p);
        let params = s.params;
        if let (Some(end), false) = (self.lambda_end, self.arc_control) {
            let remaining = end - state.t;
            if remaining.abs() <= 1e-12 * end.abs().max(1.0) {
                return Ok(None);
            }
            if p.control.size.abs() > remaining.abs() {
                p.control.size = remaining;
            }
        }
        if let Control::Displacement { delta, .. } = &params.control {
            let remaining = delta - p.travelled;
            if remaining.abs() <= 1e-12 * delta.abs() {
                return Ok(None);
            }
            if p.control.size.abs() > remaining.abs() {
                p.control.size = remaining;
            }
        }
        Ok(Some(match &params.control {
            Control::Load { .. } => Increment::Load(p.control.size),
            Control::Displacement { node, dof, .. } => {
                let Slot::Free(eq) = s.system.dofs.slots[*node][dof.index()] else {
                    unreachable!("checked by Walk::new")
                };
                Increment::Displacement {
                    eq,
                    delta: p.control.size,
                }
            }
            Control::ArcLength {
                direction,
                initial_increment,
                lambda_end,
                max_increment_factor,
                ..
            } => {
                if p.arc_ds.is_none() {
                    // First step: the arc length that gives the requested load-factor increment.
                    if !s.fresh {
                        s.assemble(state);
                    }
                    let dq_b = match s.solve_pair() {
                        Ok((_, b)) => b,
                        Err(e) => {
                            self.path.error = Some(e);
                            return Ok(None);
                        }
                    };
                    let ds = initial_increment * (s.dot_w(&dq_b, &dq_b) + s.c_lambda).sqrt();
                    if !(ds.is_finite() && ds > 0.0) {
                        return Err(Error::InvalidModel(
                            "arc-length control: the loads and prescribed motions act on no free DOF (they are all on \
                             constrained DOFs, or do not change with the load factor), so the path has no direction; \
                             load a free DOF, or prescribe a motion that changes with the load factor"
                                .into(),
                        ));
                    }
                    p.arc_ds = Some(ds);
                    p.control.size = ds;
                    p.control.max_size = ds * max_increment_factor;
                    p.control.min_size = 1e-14 * ds / initial_increment * self.scale;
                }
                // Without a previous increment (first step, or after a jump) head for lambda_end.
                let towards = (lambda_end - state.t).signum();
                let towards = if towards == 0.0 { *direction } else { towards };
                match p.restart {
                    // After a jump or a branch switch the state may carry a neutral mode (a fold
                    // free to slide) that makes the tangent direction of the path undefined: the
                    // path restarts with a load increment, which fixes the direction of travel.
                    Some(dl) => Increment::Load(towards * dl),
                    None => Increment::Arc {
                        ds: p.control.size.abs(),
                        direction: towards,
                    },
                }
            }
        }))
    }

    /// A failed increment: back to the converged `saved` state with half the increment; once the
    /// halvings run out, on the stable path of a slowly driven test, a relaxation at a larger load
    /// factor, else the end of the path.
    fn reject(&mut self, state: &mut State, saved: State, rejection: &Rejection) -> Flow {
        *state = saved;
        self.s.invalidate();
        self.s.stats.cutbacks += 1;
        self.p.neutral_reached = false;
        log::debug!("increment rejected at t = {}: {rejection}; cutting back", state.t);
        let params = self.s.params;
        if let Err(why) = self.p.control.reject() {
            // On the stable path of a slowly driven test, a state whose tangent does not define
            // the path (a neutral mode: a fold free to slide) can still be left by relaxing at a
            // larger load factor.
            return match self.relax_onward(state) {
                Some(flow) => flow,
                None => {
                    let force = self.s.reference_force();
                    self.path.error = Some(give_up(&self.p, why, rejection, state, params, force));
                    Flow::Stop
                }
            };
        }
        self.s.strict_turns = self.p.control.cutbacks < params.max_cutbacks / 2;
        self.s.tangent_predictor = false;
        // A restarting load increment that fails (the branch ends in a snap): back to the arc
        // length, which turns at the limit.
        self.p.restart = None;
        Flow::Next
    }

    /// On the path of a slowly driven test, from the converged `state` where the arc length gets
    /// nowhere: a relaxation past a limit point (a jump), else at the load factor one first step
    /// further (a fold's neutral mode keeps every relaxed state near this one: the path goes on
    /// along the same stable branch). `None` if neither finds a stable equilibrium (`state`
    /// unchanged) or the path is not such a path.
    fn relax_onward(&mut self, state: &mut State) -> Option<Flow> {
        let (true, Some(end), Some(ds), Some(first)) = (
            self.s.params.jump_at_limit_points && self.arc_control,
            self.lambda_end,
            self.p.arc_ds,
            self.first_increment(),
        ) else {
            return None;
        };
        let from = state.clone();
        let travel = (end - from.t).signum();
        let t_next = from.t + travel * first.min((end - from.t).abs());
        let switching = self.switching();
        let relaxed = self
            .s
            .jump(state, &from, travel, self.p.last_dlambda, ds)
            .or_else(|e| {
                if switching {
                    self.s.relax_at(state, &from, t_next)
                } else {
                    Err(e)
                }
            });
        if let Err(e) = relaxed {
            log::debug!("no relaxation past t = {}: {e}", from.t);
            *state = from;
            return None;
        }
        log::debug!("path continued by relaxation from t = {} to t = {}", from.t, state.t);
        let relaxed = Relaxed {
            // Paths that switch branches record how far the state moved.
            distance: if switching { self.s.distance(state, &from) } else { ds },
            jump: false,
            event: None,
        };
        if !self.push_relaxed(state, relaxed) {
            return Some(Flow::Stop);
        }
        self.p.control.size = ds;
        Some(Flow::Next)
    }

    /// Branches are switched on this path (a slowly driven test with branch switching).
    fn switching(&self) -> bool {
        let params = self.s.params;
        params.switch_branches && params.jump_at_limit_points && self.arc_control
    }

    /// On the path of a slowly driven test with branch switching, the accepted steps crawl: the
    /// last [`CRAWL_STEPS`] each moved the load factor by less than [`CRAWL`] of the first step's
    /// (a fold's neutral mode takes up their arc length). The path then goes on by relaxation.
    fn crawling(&mut self, dlambda: f64) -> bool {
        let Some(first) = self.first_increment().filter(|_| self.switching()) else {
            return false;
        };
        if dlambda.abs() >= CRAWL * first {
            self.p.crawl = 0;
            return false;
        }
        self.p.crawl += 1;
        if self.p.crawl < CRAWL_STEPS {
            return false;
        }
        self.p.crawl = 0;
        true
    }

    /// The load-factor increment of an arc-length path's first step (`initial_increment`).
    fn first_increment(&self) -> Option<f64> {
        match &self.s.params.control {
            Control::ArcLength { initial_increment, .. } => Some(initial_increment.abs()),
            _ => None,
        }
    }

    /// On the path of a slowly driven test, a converged step over which the monitored reaction
    /// changes by more than [`COARSE`] times `refine_change` (and the load factor by more than
    /// `refine_span`): it may have stepped over a limit point, whose jump would then be missed,
    /// and refinement along its chord cannot recover a path that turned in between. So is a step
    /// that needs refinement (a change above `refine_change`) which the refinement cannot draw,
    /// or whose refinement finds an unstable state between stable ends.
    /// It is rolled back to `saved` with half the increment (`true`), while half the cut-backs
    /// remain.
    fn too_coarse(&mut self, state: &mut State, saved: &State) -> bool {
        let params = self.s.params;
        let (true, Some(i), Some(last)) = (self.switching() && self.locate, self.monitor, self.p.history.last()) else {
            return false;
        };
        let m = self.s.asm.f_int_c[i] - self.s.asm.f_ext_c[i];
        let dm = (m - last.monitor).abs();
        let scale = m.abs().max(last.monitor.abs());
        // A step too coarse is one that needs refinement, and more (none without `refine_change`).
        if !params.wants_refinement(state.t - saved.t, last.monitor, m)
            || self.p.control.cutbacks >= params.max_cutbacks / 2
        {
            return false;
        }
        // A step the refinement cannot draw (no equilibrium on its first plane: the path curves
        // away from the chord, as over the equal-sense tape's heel on unloading) is retried
        // shorter too, or the curve would be left with a long straight segment there; so is a
        // step between stable states whose first plane finds an unstable one (an instability
        // stepped over, which a shorter step meets).
        let coarse = dm > COARSE * params.refine_change * scale
            || match first_plane(&mut self.s, saved, state) {
                Ok(Some(true)) => false,
                // The ends' stability, only where it matters (the driver's pieces are `state`'s).
                Ok(Some(false)) => {
                    self.p.last_negative == Some(0) && self.s.negative_eigenvalues().is_ok_and(|n| n == 0)
                }
                Ok(None) | Err(_) => true,
            };
        coarse && self.retry_shorter(state, saved)
    }

    /// On a path that does not switch branches, a converged step across the zero of the monitored
    /// reaction the path is to stop at, from a state of one stability count to one of another,
    /// where no state on the step's chord brings the reaction to zero: the path between the two
    /// states is not the chord the search follows (an instability lies between them). It is
    /// retried shorter while half the cut-backs remain, then taken (the search after it then
    /// warns). Measured on the set-up's push at t = 0.12 mm, E = 220 GPa (5 mm meshes): a step
    /// of 4.4 mm of push from a stable state went past a limit point 0.4 mm short of zero and the
    /// snap after it, the reaction changed sign on the unstable branch beyond, and the path went
    /// on without the folded equilibrium that shorter steps reach after the snap. Left to the
    /// search after the step: a reaction that jumps across zero with the stability unchanged (a
    /// load switched off within the step), steps that turn back at a limit point (the jump's),
    /// the path's first step (no count before it), and paths that switch branches (their counts
    /// leave neutral modes out; their steps that refinement cannot draw are retried shorter by
    /// `Walk::too_coarse`).
    fn zero_stepped_over(&mut self, state: &mut State, saved: &State, out: &Outcome) -> Result<bool> {
        let params = self.s.params;
        let (true, true, false, Some(i), Some(before)) = (
            self.locate && params.stop_at_monitor_zero != ZeroStop::Never,
            params.stability,
            self.switching(),
            self.monitor,
            self.p.last_negative,
        ) else {
            return Ok(false);
        };
        if self.p.control.cutbacks >= params.max_cutbacks / 2 {
            return Ok(false);
        }
        if let (true, Some(end)) = (self.arc_control, self.lambda_end) {
            if (state.t - saved.t) * (end - saved.t) < 0.0 {
                return Ok(false);
            }
        }
        let monitor = self.s.asm.f_int_c[i] - self.s.asm.f_ext_c[i];
        // A copy: the watch itself moves on when the state is recorded.
        let mut watch = self.p.zero;
        if !watch.crossed(monitor, self.s.zero_floor()) {
            return Ok(false);
        }
        // The plain count, as recorded (the factorisation is the one the record takes).
        let Ok(after) = self
            .s
            .factorise()
            .and_then(|()| self.s.system.linear.negative_eigenvalues())
        else {
            return Ok(false);
        };
        if after == before {
            return Ok(false);
        }
        self.p.history.push(Point {
            state: state.clone(),
            arc: self.p.arc + self.s.arc_norm(&out.dq, out.dlambda),
            monitor,
        });
        let search = zero_ahead(&mut self.s, &self.p.history);
        self.p.history.pop();
        if let ZeroSearch::Missed { .. } = search? {
            if self.retry_shorter(state, saved) {
                log::debug!(
                    "no zero on the chord of the step from t = {} (stability count {before} -> \
                     {after}): retried shorter",
                    saved.t
                );
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Halves the increment and goes back to `saved` for a converged step the path must not take
    /// (false, leaving `state` as it is, once the controller gives up: the step is then taken).
    fn retry_shorter(&mut self, state: &mut State, saved: &State) -> bool {
        if self.p.control.reject().is_err() {
            return false;
        }
        // The step after a jump or a branch switch is a load increment of its own: halved with
        // the arc, or the same step is taken again.
        if let Some(dl) = self.p.restart.as_mut() {
            *dl *= 0.5;
            log::debug!("the restarting load increment from t = {} halved to {dl:e}", saved.t);
        }
        *state = saved.clone();
        self.s.invalidate();
        self.s.stats.cutbacks += 1;
        true
    }

    /// A converged arc-length increment from a stable state to one with more than one negative
    /// eigenvalue of the tangent stepped over several critical points at once, where a path from
    /// a stable state meets the first one alone: past the peak moment of a deep tape section
    /// (110 deg) such a step went from 0 to 7 and left the path for a tangle of unstable branches
    /// that closed on itself. It is retried shorter, until half the cut-backs are spent (critical
    /// points closer than that, as the double bifurcations of a symmetric structure, are then
    /// stepped over as before). Steps between unstable states are left alone: beside the
    /// near-neutral modes of a fold that can move along the tape, their counts flicker (a check
    /// on any change by more than one doubled the states of the thin soft tape's equal-sense path
    /// near -58 deg, to no other effect).
    fn skipped_instabilities(&mut self, state: &mut State, saved: &State) -> bool {
        let params = self.s.params;
        let (true, true, Some(0)) = (self.arc_control, params.stability, self.p.last_negative) else {
            return false;
        };
        if self.p.control.cutbacks >= params.max_cutbacks / 2 {
            return false;
        }
        // The plain count, as recorded: a neutral mode's test (one negative pivot) is not needed.
        let Ok(n) = self
            .s
            .factorise()
            .and_then(|()| self.s.system.linear.negative_eigenvalues())
        else {
            return false;
        };
        // The neutral mode a path starts with (see `Walk::stable_start`) is one of the pivots.
        if n <= 1 + usize::from(self.p.neutral_from_start) {
            return false;
        }
        log::debug!("stability count 0 -> {n} across t = {} .. {}", saved.t, state.t);
        self.retry_shorter(state, saved)
    }

    /// A converged arc-length increment that went back in load factor, on the path of a slowly
    /// driven test: jump to the stable equilibrium beyond the limit point. `None` if there is
    /// nothing to jump from (or no stable equilibrium: the path is then followed through it).
    fn jump_at_limit(&mut self, state: &mut State, saved: &State) -> Option<Flow> {
        let (true, Some(end)) = (self.s.params.jump_at_limit_points && self.arc_control, self.lambda_end) else {
            return None;
        };
        let travel = (end - saved.t).signum();
        if (state.t - saved.t) * travel >= 0.0 || self.p.last_dlambda.is_none() {
            return None;
        }
        let turned = state.clone();
        let mut limit = None;
        if self.locate && self.switching() {
            // The limit point itself, not the last state before it, is what the jump leaves from.
            let monitor = self
                .monitor
                .map_or(0.0, |i| self.s.asm.f_int_c[i] - self.s.asm.f_ext_c[i]);
            let arc = self.p.arc + self.s.distance(&turned, saved);
            let point = Point {
                state: turned.clone(),
                arc,
                monitor,
            };
            match before_jump(&mut self.s, &self.p.history, point, &mut self.path) {
                Ok(found) => limit = found,
                Err(e) => {
                    self.path.error = Some(e);
                    return Some(Flow::Stop);
                }
            }
        }
        if let Err(e) = self
            .s
            .jump(state, saved, travel, self.p.last_dlambda, self.p.control.size.abs())
        {
            // No stable equilibrium beyond this limit point (a neutral mode, such as a fold free to
            // slide, makes the gradient flow stall): the path itself is followed through it, its
            // states recorded with their stability.
            log::debug!("no jump at t = {}: {e}; following the path", saved.t);
            *state = turned;
            self.s.invalidate();
            self.s.assemble(state);
            return None;
        }
        // The state jumped to lies beyond the located limit point along the path.
        let to_limit = limit.map_or(0.0, |arc| arc - self.p.arc);
        let relaxed = Relaxed {
            distance: self.s.distance(state, saved).max(1.001 * to_limit),
            jump: true,
            event: None,
        };
        Some(if self.push_relaxed(state, relaxed) {
            Flow::Next
        } else {
            Flow::Stop
        })
    }

    /// A converged increment that went on in load factor from a stable state to an unstable one
    /// (a bifurcation), when branches are switched: leave it for the stable branch. `None` if it
    /// is not the case, or the instability is not one the state leaves (the path goes on).
    fn switch_at_bifurcation(&mut self, state: &mut State, saved: &State) -> Option<Flow> {
        if self.p.neutral_from_start {
            // The path's neutral mode, recounted as at its start (in either direction of the load
            // factor): testing it by relaxation at each state would only find it neutral again.
            match self.keeps_neutral() {
                Ok(true) => {
                    self.p.neutral_reached = true;
                    return None;
                }
                // Gone (no negative pivot left): the path's states are counted plainly from here.
                // Beside another negative pivot, or beyond round-off: this state is tested as
                // after any stable one, and the mode is still recounted at the next (the steps
                // that close in on an instability found here go back to states that keep it).
                Ok(false) => {
                    if matches!(self.s.system.linear.negative_eigenvalues(), Ok(0)) {
                        self.p.neutral_from_start = false;
                    }
                }
                Err(e) => {
                    self.path.error = Some(e);
                    return Some(Flow::Stop);
                }
            }
        }
        let forward = self
            .lambda_end
            .is_some_and(|end| (state.t - saved.t) * (end - saved.t) > 0.0);
        // A state unstable only by a neutral mode was recorded as stable: a further negative
        // pivot is tested too.
        let was_stable = self.p.last_negative == Some(0);
        if !(self.s.params.switch_branches && self.arc_control && forward && was_stable) {
            return None;
        }
        match self
            .s
            .factorise()
            .and_then(|()| self.s.system.linear.negative_eigenvalues())
        {
            Ok(0) => return None,
            Ok(_) => {}
            Err(e) => {
                self.path.error = Some(e);
                return Some(Flow::Stop);
            }
        }
        let ds = self.p.control.size.abs();
        // Closing in on an instability found real, the retried states are not tested again.
        let real = if self.p.closing_in {
            Ok(true)
        } else {
            self.s.leaves(state)
        };
        match real {
            Ok(true) => {}
            Ok(false) => {
                // A neutral mode (a fold free to slide on its plateau) or a pivot at round-off
                // level: the path goes on, its state recorded without it.
                self.p.neutral_reached = true;
                self.s.assemble(state);
                return None;
            }
            Err(e) => {
                log::debug!("no instability test at t = {}: {e}; following the path", state.t);
                self.s.invalidate();
                self.s.assemble(state);
                return None;
            }
        }
        // A long step may have jumped over a limit point onto another branch rather than met a
        // bifurcation: close in with shorter steps first (a limit point then shows as a turn in
        // load factor, and a bifurcation is located from nearby).
        if let Some(ds0) = self.p.arc_ds {
            if ds > ds0 / CLOSE_IN && self.p.control.reject().is_ok() {
                *state = saved.clone();
                self.s.invalidate();
                self.s.stats.cutbacks += 1;
                self.p.closing_in = true;
                return Some(Flow::Next);
            }
        }
        self.p.closing_in = false;
        let reached = state.clone();
        let switch = match self
            .s
            .switch_branch(state, saved, &reached, self.p.neutral_from_start)
        {
            Ok(switch) => switch,
            Err(e) => {
                // No stable branch found: the path itself is followed, its states recorded with
                // their stability.
                log::debug!("no branch switch at t = {}: {e}; following the path", reached.t);
                *state = reached;
                self.s.invalidate();
                self.s.assemble(state);
                return None;
            }
        };
        // Arc positions run from the last converged state, through the located bifurcation, to
        // the state on the new branch.
        let mut from = saved;
        if switch.critical.is_none() {
            // The steps closed in on the bifurcation within the location's tolerance: the last
            // recorded state is the last stable one.
            let arc = self.p.arc;
            if let Some(last) = self.path.steps.iter_mut().rev().find(|st| st.arc == arc) {
                last.event.get_or_insert(Event::Bifurcation);
            }
        }
        if let Some((critical, step)) = &switch.critical {
            let mut step = step.clone();
            step.arc = self.p.arc + self.s.distance(critical, saved);
            self.p.arc = step.arc;
            self.s.stats.steps += 1;
            self.path.steps.push(step);
            from = critical;
        }
        log::debug!(
            "branch switch at t = {}: potential energy {:.6e} J",
            state.t,
            switch.energy
        );
        // A branch that leaves the bifurcation continuously is reached nearby; a far one was
        // reached by a snap.
        let relaxed = Relaxed {
            distance: self.s.distance(state, from),
            jump: self.s.distance(state, &reached) > 0.5 * ds,
            event: Some(Event::BranchSwitch),
        };
        Some(if self.push_relaxed(state, relaxed) {
            Flow::Next
        } else {
            Flow::Stop
        })
    }

    /// Whether the driver's state (its tangent assembled: the path's start, or the converged state
    /// of the increment) has one negative pivot, at round-off level (see
    /// [`Driver::negative_eigenvalues`]).
    ///
    /// # Errors
    /// A failure of the linear algebra.
    fn keeps_neutral(&mut self) -> Result<bool> {
        self.s.factorise()?;
        Ok(self.s.system.linear.negative_eigenvalues()? == 1 && self.s.negative_eigenvalues()? == 0)
    }

    /// A converged arc-length increment that crossed the final load factor: the path ends with a
    /// load increment onto it from `saved` (or, if that fails, the crossing is retried shorter).
    /// `None` if it did not cross.
    fn land(&mut self, state: &mut State, saved: State) -> Option<Flow> {
        let (true, Some(end)) = (self.arc_control, self.lambda_end) else {
            return None;
        };
        let start = saved.t;
        // The first step lands too: one that overshoots lambda_end (a large initial increment)
        // would otherwise carry the path away from it.
        if (start - end) * (state.t - end) >= 0.0 {
            return None;
        }
        let mut trial = saved.clone();
        self.s.invalidate();
        if let Ok(out) = self.s.increment(&mut trial, &Increment::Load(end - start)) {
            *state = trial;
            // The path ends here (at a zero of the monitored reaction short of it if it is to
            // stop there).
            if self.record_step(state, &out) == Some(false) {
                // The progress callback's wish stops the analysis, not only this step.
                self.path.cancelled = true;
            }
            return Some(Flow::Stop);
        }
        // The final load step failed: retry the crossing with a shorter arc.
        *state = saved;
        self.s.invalidate();
        self.s.stats.cutbacks += 1;
        if let Err(why) = self.p.control.reject() {
            let force = self.s.reference_force();
            self.path.error = Some(give_up(&self.p, why, &Rejection::Landing, state, self.s.params, force));
            return Some(Flow::Stop);
        }
        Some(Flow::Next)
    }

    /// A converged increment along the path: record it, adapt the next increment (or, where the
    /// steps crawl, go on by relaxation).
    fn accept(&mut self, state: &mut State, saved: &State, out: Outcome) -> Flow {
        let restarted = self.p.restart.take().is_some();
        self.p.closing_in = false;
        self.s.strict_turns = true;
        self.s.tangent_predictor = true;
        let Some(keep_going) = self.record_step(state, &out) else {
            return Flow::Stop;
        };
        if self.p.stopped_at_zero {
            // The progress callback's wish stops the analysis, not only this step.
            self.path.cancelled = !keep_going;
            return Flow::Stop;
        }
        // Adapt the increment to the Newton effort.
        self.p.control.accept(out.iterations);
        if let (true, Some(first)) = (restarted, self.p.arc_ds) {
            // The path restarted from a relaxed state (a jump, a branch switch) with a load
            // increment: the arc goes on from that increment's, not from the one inherited from
            // the branch left behind, which can be far longer (85 times on the equal-sense tape's
            // unloading, where a jump lands 0.05 deg from the limit point of the branch it
            // reaches, and an arc that long went round that limit onto the unstable side), but
            // not below a part of the path's first arc (a restart after crawling steps is tiny).
            let arc = (RESTART_ARC * self.s.arc_norm(&out.dq, out.dlambda)).max(first / RESTART_FLOOR);
            if arc < self.p.control.size.abs() {
                self.p.control.size = self.p.control.size.signum() * arc;
            }
        }
        if let (true, Some(end)) = (self.arc_control, self.lambda_end) {
            // A first step from a start at the end has not reached it by leaving it; one that lands
            // on it exactly (a linear response: `land` takes only steps that cross) has.
            let reached = (state.t - end) * (saved.t - end) <= 0.0;
            if reached && (self.p.last_dlambda.is_some() || saved.t != end) {
                return Flow::Stop;
            }
        }
        if let Some(back) = self
            .p
            .memory
            .as_mut()
            .and_then(|m| m.visit(state, &self.s.system.reference, self.p.last_negative))
        {
            let end = self.lambda_end.unwrap_or(f64::NAN);
            let detail = if back.reversed {
                format!(
                    "it turned back at t = {:.6e} and is retracing the path it followed, through the states of \
                     increment {} (t = {:.6e}); it would only repeat them until the step limit. lambda_end = {end} \
                     was not reached: it may lie beyond the load factor the structure carries on this path, or a \
                     step jumped across a sharp turn (a smaller initial_increment or max_increment_factor keeps \
                     the steps on the path)",
                    back.t_turn, back.increment_old, back.t_old
                )
            } else {
                format!(
                    "it closed a loop, passing again in the same sense through the states of increment {} \
                     (t = {:.6e}); it would only go round until the step limit. lambda_end = {end} is not on this \
                     loop",
                    back.increment_old, back.t_old
                )
            };
            self.path.error = Some(Error::PathReturned {
                step: None,
                t: state.t,
                detail,
            });
            return Flow::Stop;
        }
        self.p.last_dlambda = Some(out.dlambda);
        self.s.previous = Some((out.dq, out.dlambda));
        if !keep_going {
            self.path.cancelled = true;
            return Flow::Stop;
        }
        self.p.steps_left = self.p.steps_left.saturating_sub(1);
        if self.crawling(out.dlambda) {
            return self.relax_onward(state).unwrap_or(Flow::Next);
        }
        Flow::Next
    }

    /// Records the converged `state` reached by the increment `out` (and what is located or
    /// refined after it; at a zero of the monitored reaction where the path is to stop, `state`
    /// becomes that zero's, see [`Self::stop_at_zero`]); `Some(keep_going)` as the progress
    /// callback says, `None` on an error (recorded on the path).
    fn record_step(&mut self, state: &mut State, out: &Outcome) -> Option<bool> {
        self.p.max_load = self.p.max_load.max(self.s.force_norm(&self.s.asm.f_ext));
        self.p.unresolved = self
            .s
            .unresolved(out.residual, self.p.max_load, state.t, out.iterations);
        if self.p.unresolved.is_some() && self.p.first_unresolved.is_none() {
            self.p.first_unresolved = Some((state.t, self.p.max_load));
        }
        let mut step = match self.s.record(state, out) {
            Ok(st) => st,
            Err(e) => {
                self.path.error = Some(e);
                return None;
            }
        };
        if std::mem::take(&mut self.p.neutral_reached) {
            step.negative_eigenvalues = step.negative_eigenvalues.map(|n| n.saturating_sub(1));
        }
        self.p.arc += self.s.arc_norm(&out.dq, out.dlambda);
        step.arc = self.p.arc;
        self.s.stats.steps += 1;
        let keep_going = (self.progress)(&step, &self.s.stats);
        self.p.last_negative = step.negative_eigenvalues;
        self.path.steps.push(step);
        if let Control::Displacement { .. } = &self.s.params.control {
            self.p.travelled += self.p.control.size;
        }
        if self.locate {
            self.push_history(state);
            if let Err(e) = after_step(&mut self.s, &self.p.history, &mut self.path) {
                self.path.error = Some(e);
                return None;
            }
            // Set only where the path is to stop at a zero (`push_history`).
            if std::mem::take(&mut self.p.zero_crossed) {
                match zero_to_stop_at(&mut self.s, &self.p.history) {
                    Ok(ZeroSearch::Found(found)) => self.stop_at_zero(state, *found),
                    Ok(other) => other.warn_if_missed(),
                    Err(e) => {
                        self.path.error = Some(e);
                        return None;
                    }
                }
            }
        }
        Some(keep_going)
    }

    /// Ends the path at the located zero `found` of the monitored reaction: the states recorded
    /// beyond it (the last converged one, and any located or refined after it) are dropped, and
    /// the step ends in that zero's state.
    fn stop_at_zero(&mut self, state: &mut State, found: Found) {
        let arc = found.step.arc;
        self.path.steps.retain(|st| st.arc <= arc);
        // The step's end is judged at the zero, not at the state dropped.
        let st = &found.step;
        self.p.unresolved = self
            .s
            .unresolved(st.residual, self.p.max_load, st.lambda, st.iterations);
        self.s.stats.steps += 1;
        self.path.steps.push(found.step);
        *state = found.state;
        self.p.stopped_at_zero = true;
    }

    /// Appends `state` (with the monitored reaction of the last assembly) to the history of the
    /// location of events.
    fn push_history(&mut self, state: &State) {
        let monitor = self
            .monitor
            .map_or(0.0, |i| self.s.asm.f_int_c[i] - self.s.asm.f_ext_c[i]);
        if self.s.params.stop_at_monitor_zero != ZeroStop::Never {
            self.p.zero_crossed = self.p.zero.crossed(monitor, self.s.zero_floor());
        }
        self.p.history.push(Point {
            state: state.clone(),
            arc: self.p.arc,
            monitor,
        });
    }

    /// Records `state`, reached by relaxation, and restarts the path from it (no previous
    /// increment, a restarting load increment, a new location history holding it); `false` if the
    /// analysis must stop (a failed record, or the progress callback's wish).
    fn push_relaxed(&mut self, state: &State, relaxed: Relaxed) -> bool {
        self.p.unresolved = None;
        let outcome = Outcome {
            iterations: 0,
            residual: 0.0,
            dq: Vec::new(),
            dlambda: 0.0,
        };
        let mut st = match self.s.record(state, &outcome) {
            Ok(st) => st,
            Err(e) => {
                self.path.error = Some(e);
                return false;
            }
        };
        // Relaxation ends where the tangent is positive definite but for a neutral mode.
        if st.negative_eigenvalues == Some(1) && self.switching() {
            match self.s.negative_eigenvalues() {
                Ok(n) => st.negative_eigenvalues = Some(n),
                Err(e) => {
                    self.path.error = Some(e);
                    return false;
                }
            }
        }
        st.jump = relaxed.jump;
        st.event = relaxed.event;
        self.p.arc += relaxed.distance;
        st.arc = self.p.arc;
        self.p.last_negative = st.negative_eigenvalues;
        self.s.stats.steps += 1;
        let keep_going = (self.progress)(&st, &self.s.stats);
        self.path.steps.push(st);
        self.s.previous = None;
        if let Some(m) = &mut self.p.memory {
            m.restart(state, &self.s.system.reference, self.p.last_negative);
        }
        self.p.restart = self.p.last_dlambda.map(|dl| 0.5 * dl.abs());
        self.p.neutral_reached = false;
        // The restarting state's own count governs from here.
        self.p.neutral_from_start = false;
        self.p.closing_in = false;
        self.p.control.cutbacks = 0;
        self.p.history.clear();
        if self.locate {
            self.push_history(state);
        }
        if !keep_going {
            self.path.cancelled = true;
        }
        keep_going
    }

    /// The path as it ends: the step limit reported, located states in path order, statistics.
    fn finish(mut self, state: &State, start: Instant, linear_counts: (usize, usize)) -> Result<StaticPath> {
        if let (true, Some(end), Control::ArcLength { max_steps, .. }) =
            (self.arc_control, self.lambda_end, &self.s.params.control)
        {
            let short = (state.t - end).abs() > 1e-9 * end.abs().max(1.0);
            if self.path.error.is_none() && !self.path.cancelled && short && !self.p.stopped_at_zero {
                self.path.error = Some(Error::StepLimit {
                    step: None,
                    t: state.t,
                    clock: Clock::LoadFactor,
                    steps: *max_steps,
                    target: end,
                });
            }
        }
        // Only the step's end is judged: on the way its first increments may carry loads the
        // model cannot resolve while the step's own load is resolved. A step that fails after
        // such states says so (there, Newton stalls at the next increments: a 10 m thick steel
        // plate loaded to 1 N in 1000 increments, from 1 mN, failed at 1.9 mN).
        let last = self.p.unresolved.take();
        if let (Some(e), None, false) = (last, &self.path.error, self.path.cancelled) {
            self.path.error = Some(e);
        } else if let (Some(Error::NotConverged { detail, .. }), Some((lambda, load))) =
            (&mut self.path.error, self.p.first_unresolved)
        {
            detail.push_str(&format!(
                "; at load factor {lambda:.6e} the step's loads ({load:.3e} N) were below the \
                 model's force resolution (a state out of equilibrium by more than {RESOLUTION:e} \
                 of them): raise the loads or check the section's units"
            ));
        }
        if self.locate {
            self.path.steps.sort_by(|a, b| a.arc.total_cmp(&b.arc));
        }
        let s = &mut self.s;
        s.stats.refinement_sweeps = s.system.linear.refinement_sweeps - linear_counts.0;
        s.stats.lu_fallbacks = s.system.linear.lu_fallbacks - linear_counts.1;
        s.stats.wall_s = start.elapsed().as_secs_f64();
        self.path.stats = s.stats;
        Ok(self.path)
    }
}

/// The error that ends a path whose increment could not be made to converge.
/// `force` is the reference force of the convergence test \[N\].
fn give_up(p: &PathState, why: GiveUp, last: &Rejection, state: &State, params: &StaticParams, force: f64) -> Error {
    let (iterations, residual) = last.newton();
    let how = match why {
        // Under load control the load factor tried names a value out of scale (lambda_end = 1e300
        // failed as "cut back 10 times; the residual became non-finite" at load factor 0).
        GiveUp::Cutbacks => match params.control {
            Control::Load { .. } => format!(
                "increment cut back {} times, the last to load factor {:.3e}",
                params.max_cutbacks,
                state.t + p.control.size
            ),
            _ => format!("increment cut back {} times", params.max_cutbacks),
        },
        GiveUp::RoundOff => format!("increment cut back to {:.3e}, below round-off", p.control.size.abs()),
    };
    let tol = params.newton.tol_force * force;
    // Newton brought the residual to a millionth of the forces but not to the tolerance: the
    // tolerance is below what floating point resolves here (small loads against E t L), not a
    // limit point.
    let precision = matches!(last, Rejection::NotConverged { .. }) && residual <= 1e-6 * force && residual > tol;
    let hint = match params.control {
        _ if precision => format!(
            "; the residual stopped at {residual:.3e} N, {:.1e} of the forces ({force:.3e} N) but above the \
             tolerance tol_force = {} of them: the loads are small against the structure's stiffness and \
             round-off stops Newton there; pass a larger tol_force (e.g. 1e-6)",
            residual / force,
            params.newton.tol_force
        ),
        Control::Load { .. } | Control::Displacement { .. } => {
            "; if the structure reached a limit point (a snap), arc-length control follows it".to_owned()
        }
        Control::ArcLength { .. } => String::new(),
    };
    Error::NotConverged {
        step: None,
        t: state.t,
        clock: Clock::LoadFactor,
        iterations,
        residual,
        detail: format!("{how}; last failure: {last}{hint}"),
    }
}

//! Static equilibrium paths: `r(q, lambda) = f_int(q) - lambda f_ext = 0` at the free DOFs, with
//! the constrained DOFs at `lambda * value`.
//!
//! Every increment is a bordered Newton iteration: with `K = dr/dq` and
//! `b = -dr/dlambda = f_ext - K_fc * values`, each iteration solves `K dq_r = -r` and `K dq_b = b`
//! (one factorisation, two solves) and sets `dq = dq_r + dlambda dq_b`, where `dlambda` comes from
//! the control equation: zero (load control), the controlled DOF fixed (displacement control, Batoz
//! & Dhatt 1979), or the arc-length constraint
//! `|Dq|_W^2 + Dlambda^2 c = Ds^2` (Crisfield 1981), whose root is chosen at the smallest angle with
//! the predictor. The first predictor follows the tangent in the requested direction; later ones
//! follow the tangent at the converged state (when its factorisation is at hand from the
//! stability count) oriented like the previous increment (Feng et al. 1996), or else, and always
//! after a cut-back, extrapolate the previous converged increment (secant predictor). A converged
//! increment that turns back on the path (negative inner product with the previous one) is
//! rejected and cut back, and one that bends by more than 60 degrees is refined, so limit points,
//! snap-through and snap-back are passed without reversing or jumping branches. Norms weigh rotations by the
//! characteristic length `L_c` of the model.
//!
//! An increment that fails (no convergence, singular tangent, no arc-length root, non-finite
//! values) is restarted from the last converged state with half the increment, up to
//! `max_cutbacks` times; then the analysis stops with [`Error::NotConverged`] and the path so far.

use std::time::Instant;

use super::{Control, StaticParams, StaticPath, StaticStep, Stats};
use crate::assembly::{Assembled, System};
use crate::dof::Slot;
use crate::element::shell::ElementStress;
use crate::error::{Error, Result};
use crate::linalg::LinearSolver;
use crate::state::State;

/// What one increment does.
#[derive(Clone, Copy, Debug)]
enum Increment {
    Load(f64),
    Displacement { eq: usize, delta: f64 },
    Arc { ds: f64, direction: f64 },
}

struct Outcome {
    iterations: usize,
    residual: f64,
    dq: Vec<f64>,
    dlambda: f64,
}

struct Solver<'a> {
    system: &'a mut System,
    linear: LinearSolver,
    asm: Assembled,
    /// `asm` holds residual and tangent of the current state.
    fresh: bool,
    /// `linear` holds the factorisation of `asm`'s tangent.
    factorised: bool,
    /// Element stresses of the mixed iteration at the current state (linearised from the last
    /// iterate), used by the next tangent when `stress_valid`.
    stress: Vec<ElementStress>,
    stress_valid: bool,
    /// Residual norm reachable in floating point [N]: a few ulps of the element forces.
    round_off: f64,
    /// Largest reference force met on the path so far [N] (the force scale near zero load).
    path_force: f64,
    /// Reject arc-length steps that bend sharply (cleared after repeated cut-backs).
    strict_turns: bool,
    /// Use the tangent predictor when a factorisation of the converged state is at hand (off
    /// after a cut-back: the secant predictor is safer at sharp turns).
    tangent_predictor: bool,
    /// Increment of the last converged step, for the arc-length secant predictor.
    previous: Option<(Vec<f64>, f64)>,
    weights: Vec<f64>,
    values: Vec<f64>,
    c_lambda: f64,
    params: &'a StaticParams,
    stats: Stats,
    force_floor: f64,
}

impl Solver<'_> {
    fn assemble(&mut self, state: &State) {
        let t = Instant::now();
        let stress = self.stress_valid.then_some(self.stress.as_slice());
        self.system
            .assemble_mixed(state, true, stress, &mut self.asm);
        self.stats.assembly_s += t.elapsed().as_secs_f64();
        self.fresh = true;
        self.factorised = false;
    }

    /// Moves `state` by `(dq, dlambda)`; in the mixed iteration the element stresses follow the
    /// linearised kinematics of that move.
    fn advance(&mut self, state: &mut State, dq: &[f64], dlambda: f64) {
        if self.params.newton.mixed_stress {
            let t = Instant::now();
            self.system
                .linearised_stresses(state, dq, dlambda, &mut self.stress);
            self.stats.assembly_s += t.elapsed().as_secs_f64();
            self.stress_valid = true;
        }
        self.system.update(state, dq, dlambda);
    }

    /// Forgets everything computed at the current state (after it was replaced).
    fn invalidate(&mut self) {
        self.fresh = false;
        self.factorised = false;
        self.stress_valid = false;
    }

    fn dot_w(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.weights)
            .map(|((x, y), w)| w * x * y)
            .sum()
    }

    fn force_norm(&self, f: &[f64]) -> f64 {
        f.iter()
            .zip(&self.weights)
            .map(|(v, w)| v * v / w)
            .sum::<f64>()
            .sqrt()
    }

    fn reaction_norm(&self) -> f64 {
        let lc2 = self.system.char_length.powi(2);
        self.system
            .dofs
            .constrained
            .iter()
            .zip(&self.asm.reactions)
            .map(|(c, r)| if c.dof.is_rotation() { r * r / lc2 } else { r * r })
            .sum::<f64>()
            .sqrt()
    }

    fn reference_force(&self, lambda: f64) -> f64 {
        (lambda.abs() * self.force_norm(&self.asm.f_ext))
            .max(self.reaction_norm())
            .max(self.force_floor)
    }

    /// `b = f_ext - K_fc values`.
    fn load_vector(&self) -> Vec<f64> {
        let mut b = self.asm.f_ext.clone();
        let mut kv = vec![0.0; b.len()];
        self.system
            .pattern_fc
            .mul_add(&self.asm.k_fc, &self.values, &mut kv);
        for (bi, k) in b.iter_mut().zip(kv) {
            *bi -= k;
        }
        b
    }

    /// Factorises the current tangent and returns `(dq_r, dq_b)`.
    fn solve_pair(&mut self) -> Result<(Vec<f64>, Vec<f64>)> {
        let t = Instant::now();
        if !self.factorised {
            self.linear.factorize(&self.asm.k_ff)?;
            self.stats.factorisations += 1;
            self.factorised = true;
        }
        let mut dq_r: Vec<f64> = self.asm.residual.iter().map(|r| -r).collect();
        self.linear.solve_in_place(&mut dq_r)?;
        let mut dq_b = self.load_vector();
        self.linear.solve_in_place(&mut dq_b)?;
        self.stats.solve_s += t.elapsed().as_secs_f64();
        Ok((dq_r, dq_b))
    }

    fn converged(&self, lambda: f64, energy: Option<(f64, f64)>) -> (bool, f64) {
        let res = self.force_norm(&self.asm.residual);
        let tol = self.params.newton.tol_force * self.reference_force(lambda);
        let ok_force = res <= tol.max(self.round_off);
        // The energy ratio cannot go below round-off on tiny increments: a residual a hundred times
        // below the force tolerance, or at the round-off floor, is converged whatever the energy
        // ratio says.
        let ok_energy = energy.is_none_or(|(first, last)| last <= self.params.newton.tol_energy * first)
            || res <= (0.01 * tol).max(self.round_off);
        (ok_force && ok_energy && res.is_finite(), res)
    }

    /// One increment from the converged `state`; on error the state is left modified.
    #[allow(clippy::too_many_lines)]
    fn increment(&mut self, state: &mut State, inc: Increment) -> Result<Outcome> {
        if !self.fresh {
            self.assemble(state);
        }
        let tangent_predictor = self.factorised && self.tangent_predictor;
        let (dlambda0, dq) = match (inc, &self.previous) {
            (Increment::Arc { ds, .. }, Some((prev_dq, prev_dl))) if tangent_predictor => {
                // Tangent predictor from the factorisation already made for the stability count,
                // oriented like the previous increment (Feng et al. 1996).
                let mut dq_b = self.load_vector();
                self.linear.solve_in_place(&mut dq_b)?;
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
            _ => {
                let (dq_r, dq_b) = self.solve_pair()?;
                let (dlambda0, mut dq) = match inc {
                    Increment::Load(dl) => (dl, dq_r),
                    Increment::Displacement { eq, delta } => {
                        if dq_b[eq].abs() < 1e-300 {
                            return Err(Error::Factorisation(
                                "the controlled DOF does not respond to the load".into(),
                            ));
                        }
                        ((delta - dq_r[eq]) / dq_b[eq], dq_r)
                    }
                    Increment::Arc { ds, direction } => {
                        let norm = (self.dot_w(&dq_b, &dq_b) + self.c_lambda).sqrt();
                        (direction * ds / norm, vec![0.0; dq_b.len()])
                    }
                };
                for (d, b) in dq.iter_mut().zip(&dq_b) {
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
        // Smallest residual so far and the iteration that reached it: an iteration that has not
        // improved on it for `stall_iterations` iterations is cycling, not converging, and is cut
        // back at once rather than after `max_iterations`.
        let stall_n = self.params.newton.stall_iterations;
        let mut best = (f64::INFINITY, 0);
        let mut stalled = None;
        for it in 1..=max_it {
            self.stats.iterations += 1;
            self.assemble(state);
            let (ok, r) = self.converged(state.lambda, energy_first);
            res = r;
            log::trace!("Newton iteration {it}: lambda {:.6}, residual {res:.3e}", state.lambda);
            if !res.is_finite() {
                return Err(Error::Factorisation("non-finite residual".into()));
            }
            if ok {
                return self.accept(inc, it, res, acc, acc_lambda);
            }
            if res < best.0 {
                best = (res, it);
            }
            if stall_n > 0 && it >= best.1 + stall_n {
                stalled = Some(it);
                break;
            }
            if it == max_it {
                break;
            }
            let (dq_r, dq_b) = self.solve_pair()?;
            let dl = match inc {
                Increment::Load(_) => 0.0,
                Increment::Displacement { eq, .. } => -dq_r[eq] / dq_b[eq],
                Increment::Arc { ds, .. } => {
                    let u: Vec<f64> = acc.iter().zip(&dq_r).map(|(a, r)| a + r).collect();
                    let a = self.dot_w(&dq_b, &dq_b) + self.c_lambda;
                    let b = 2.0 * (self.dot_w(&dq_b, &u) + acc_lambda * self.c_lambda);
                    let c = self.dot_w(&u, &u) + acc_lambda * acc_lambda * self.c_lambda - ds * ds;
                    let disc = b * b - 4.0 * a * c;
                    if disc < 0.0 {
                        no_root += 1;
                        if no_root > 2 {
                            return Err(Error::Factorisation(
                                "the arc-length constraint has no real root".into(),
                            ));
                        }
                        -b / (2.0 * a)
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
            };
            let step: Vec<f64> = dq_r.iter().zip(&dq_b).map(|(r, b)| r + dl * b).collect();
            let e = self
                .asm
                .residual
                .iter()
                .zip(&step)
                .map(|(r, s)| r * s)
                .sum::<f64>()
                .abs();
            let energy = match energy_first {
                None => {
                    energy_first = Some((e.max(1e-300), e));
                    energy_first
                }
                Some((first, _)) => Some((first, e)),
            };
            energy_first = energy;
            // Converged in force, and the correction just computed is negligible in energy: accept
            // the current state (its tangent is factorised, ready for the stability check and the
            // next predictor) instead of paying an assembly to confirm what the energy says.
            if let Some((first, last)) = energy {
                if it > 1 && last <= self.params.newton.tol_energy * first && self.converged(state.lambda, None).0 {
                    return self.accept(inc, it, res, acc, acc_lambda);
                }
            }
            let mut alpha = 1.0;
            let saved =
                (!matches!(inc, Increment::Arc { .. }) && self.params.newton.line_search).then(|| state.clone());
            loop {
                let scaled: Vec<f64> = step.iter().map(|s| alpha * s).collect();
                self.advance(state, &scaled, alpha * dl);
                let Some(saved) = &saved else { break };
                if alpha < 0.1 {
                    break;
                }
                let t = Instant::now();
                self.system.assemble(state, false, &mut self.asm);
                self.stats.assembly_s += t.elapsed().as_secs_f64();
                self.fresh = false;
                let new_res = self.force_norm(&self.asm.residual);
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
        Err(Error::NotConverged {
            lambda: state.lambda,
            iterations: stalled.unwrap_or(max_it),
            residual: res,
            detail: match stalled {
                Some(_) => format!("Newton iterations stalled (no progress in {stall_n} iterations)"),
                None => "Newton iterations exhausted".into(),
            },
        })
    }

    /// A converged increment: rejected if it turned back or bent sharply on the arc-length path.
    fn accept(&self, inc: Increment, iterations: usize, residual: f64, dq: Vec<f64>, dlambda: f64) -> Result<Outcome> {
        if let (Increment::Arc { .. }, Some((prev_dq, prev_dl))) = (inc, &self.previous) {
            // A converged increment that turns back on the path means the step jumped
            // across a sharp turn: reject it so that the step is cut back.
            let dot = self.dot_w(&dq, prev_dq) + dlambda * prev_dl * self.c_lambda;
            let norms = ((self.dot_w(&dq, &dq) + dlambda * dlambda * self.c_lambda)
                * (self.dot_w(prev_dq, prev_dq) + prev_dl * prev_dl * self.c_lambda))
                .sqrt();
            if dot <= 0.0 {
                return Err(Error::Factorisation(
                    "the arc-length step turned back on the path".into(),
                ));
            }
            // A bend of more than 60 degrees in one step may have jumped to another branch (seen on a
            // 4 mm tape unloading past the heel): refine (the driver accepts it once half of the
            // cut-backs are spent).
            if dot < 0.5 * norms && self.strict_turns {
                return Err(Error::Factorisation(
                    "the arc-length step bent by more than 60 degrees".into(),
                ));
            }
        }
        Ok(Outcome {
            iterations,
            residual,
            dq,
            dlambda,
        })
    }

    fn record(&mut self, state: &State, out: &Outcome) -> Result<StaticStep> {
        let negative_eigenvalues = if self.params.stability {
            let t = Instant::now();
            // The LDL^T of the converged tangent is the one factorised for the convergence check.
            if !self.factorised {
                self.linear.factorize(&self.asm.k_ff)?;
                self.stats.factorisations += 1;
                self.factorised = true;
            }
            let n = self.linear.negative_eigenvalues()?;
            self.stats.solve_s += t.elapsed().as_secs_f64();
            Some(n)
        } else {
            None
        };
        let reference = &self.system.reference;
        let (displacements, rotations) = if self.params.record_fields {
            (
                (0..state.x.len())
                    .map(|i| state.displacement(reference, i).into())
                    .collect(),
                (0..state.x.len())
                    .map(|i| state.rotation(reference, i).into())
                    .collect(),
            )
        } else {
            (Vec::new(), Vec::new())
        };
        Ok(StaticStep {
            lambda: state.lambda,
            iterations: out.iterations,
            residual: out.residual,
            energy: self.asm.energy,
            reactions: self.asm.reactions.clone(),
            negative_eigenvalues,
            displacements,
            rotations,
            jump: false,
        })
    }

    /// Weighted distance between two configurations (translations [m], rotations times `L_c`).
    fn distance(&self, a: &State, b: &State) -> f64 {
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

    /// Moves the load factor to `lambda` and relaxes `state` to a stable equilibrium there by
    /// pseudo-transient continuation: each pseudo-time step solves
    /// `r(q) + C (q - q_k) = 0` with `C = beta diag|K|`, `beta` large enough that `K + C` is positive
    /// definite, so every step descends the potential (an implicit gradient flow); `beta` shrinks as
    /// steps succeed, ending in plain Newton at a stable equilibrium. Returns the pseudo-steps used.
    fn relax(&mut self, state: &mut State, lambda: f64) -> Result<usize> {
        const MAX_STEPS: usize = 400;
        let n = self.system.n_free();
        let zero = vec![0.0; n];
        self.system.update(state, &zero, lambda - state.lambda);
        // A gradient flow on the true potential: exact tangents.
        self.invalidate();
        let diag: Vec<usize> = (0..n)
            .map(|i| {
                self.system
                    .pattern_ff
                    .find(i, i)
                    .expect("diagonal entries are in the pattern")
            })
            .collect();
        let mut beta: f64 = 1e-2;
        for step in 0..MAX_STEPS {
            self.assemble(state);
            let (ok, rr) = self.converged(state.lambda, None);
            log::trace!("relaxation step {step}: beta {beta:.1e}, residual {rr:.3e}");
            if ok && beta <= 1e-6 {
                self.linear.factorize(&self.asm.k_ff)?;
                self.stats.factorisations += 1;
                self.factorised = true;
                if self.linear.negative_eigenvalues()? == 0 {
                    return Ok(step);
                }
                beta = beta.max(1e-3);
            }
            let anchor = state.clone();
            let mut acc = vec![0.0; n];
            let mut success = false;
            let mut iterations = 0;
            for it in 0..15 {
                iterations = it + 1;
                if it > 0 {
                    self.assemble(state);
                }
                let mut k = self.asm.k_ff.clone();
                let mut r = self.asm.residual.clone();
                for (i, &p) in diag.iter().enumerate() {
                    let c = beta * self.asm.k_ff[p].abs().max(1e-12);
                    k[p] += c;
                    r[i] += c * acc[i];
                }
                let res = self.force_norm(&r);
                if it > 0
                    && res <= self.params.newton.tol_force * self.reference_force(state.lambda).max(self.round_off)
                {
                    success = true;
                    break;
                }
                let t = std::time::Instant::now();
                self.linear.factorize(&k)?;
                self.stats.factorisations += 1;
                self.factorised = false;
                if self.linear.negative_eigenvalues().unwrap_or(1) > 0 {
                    // K + C must be positive definite for a descent step.
                    break;
                }
                let mut dq: Vec<f64> = r.iter().map(|v| -v).collect();
                self.linear.solve_in_place(&mut dq)?;
                self.stats.solve_s += t.elapsed().as_secs_f64();
                self.stats.iterations += 1;
                self.system.update(state, &dq, 0.0);
                for (a, d) in acc.iter_mut().zip(&dq) {
                    *a += d;
                }
            }
            // The shift that keeps K + C positive definite can be tiny next to diag|K| (a soft mode
            // of a membrane-stiff shell): let beta go down to 1e-12 before plain Newton, and grow it
            // back from there, so that soft modes are not crept along with a needlessly large shift.
            if success {
                beta /= if iterations <= 3 { 4.0 } else { 1.5 };
                if beta < 1e-12 {
                    beta = 0.0;
                }
            } else {
                *state = anchor;
                beta = (beta * 4.0).max(1e-12);
                if beta > 1e4 {
                    break;
                }
            }
        }
        Err(Error::NotConverged {
            lambda: state.lambda,
            iterations: MAX_STEPS,
            residual: self.force_norm(&self.asm.residual),
            detail: "relaxation past a limit point found no stable equilibrium".into(),
        })
    }
}

/// Follows the static equilibrium path of `system` from `state` as `params` says, calling
/// `progress` after each converged step (return `false` to stop). `state` ends at the last
/// converged configuration.
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
    let values: Vec<f64> = system.dofs.constrained.iter().map(|c| c.value).collect();
    let has_motion = values.iter().any(|v| *v != 0.0);
    let has_load = system.loads.iter().any(|l| l.value != 0.0);
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
    let linear = LinearSolver::try_new(&system.pattern_ff)?;
    let lc2 = system.char_length.powi(2);
    let c_lambda: f64 = system
        .dofs
        .constrained
        .iter()
        .map(|c| {
            if c.dof.is_rotation() {
                lc2 * c.value * c.value
            } else {
                c.value * c.value
            }
        })
        .sum();
    let weights = system.free_weights();
    let force_floor = 1e-13 * system.section.membrane[(0, 0)] * system.char_length;
    // Element forces are sums of terms of size E t |x| that cancel: the residual cannot go below a
    // few ulps of them (measured: about eps E t |x| per node).
    let x_max = system
        .reference
        .x
        .iter()
        .map(|x| x.norm())
        .fold(0.0, f64::max);
    // (Measured 2e-8 N on a 0.2 m x 2 mm steel plate where this estimate gives 2e-7 N.)
    let round_off = f64::EPSILON
        * system.section.membrane[(0, 0)]
        * (x_max + system.char_length)
        * (system.reference.x.len() as f64).sqrt();
    let mut s = Solver {
        system,
        linear,
        asm: Assembled::default(),
        fresh: false,
        factorised: false,
        stress: Vec::new(),
        stress_valid: false,
        round_off,
        path_force: 0.0,
        strict_turns: true,
        tangent_predictor: true,
        previous: None,
        weights,
        values,
        c_lambda,
        params,
        stats: Stats::default(),
        force_floor,
    };
    let mut path = StaticPath::default();

    // Load-factor increment of the last accepted step (None before the first one).
    let mut last_dlambda: Option<f64> = None;
    let mut size;
    let mut steps_left;
    let mut done_target = None;
    match &params.control {
        Control::Load { lambda_end, increments } => {
            size = (lambda_end - state.lambda) / *increments as f64;
            steps_left = usize::MAX;
            done_target = Some(*lambda_end);
        }
        Control::Displacement {
            node,
            dof,
            delta,
            increments,
        } => {
            let node = *node;
            if node >= s.system.dofs.slots.len() {
                return Err(Error::InvalidModel(format!("controlled node {node} does not exist")));
            }
            let Slot::Free(_) = s.system.dofs.slots[s.system.dofs.owner(node)][dof.index()] else {
                return Err(Error::InvalidModel(format!(
                    "controlled DOF {dof:?} of node {node} is not free"
                )));
            };
            if s.system.dofs.master[node].is_some() {
                return Err(Error::InvalidModel(format!(
                    "controlled node {node} is rigidly tied; control its reference node"
                )));
            }
            size = delta / *increments as f64;
            steps_left = *increments;
        }
        Control::ArcLength {
            initial_increment,
            direction,
            max_steps,
            ..
        } => {
            size = initial_increment * direction;
            steps_left = *max_steps;
        }
    }
    let initial_size = size.abs();
    let mut travelled = 0.0;
    let mut arc_ds: Option<f64> = None;
    let mut cutbacks = 0;
    'steps: while steps_left > 0 {
        if let Some(end) = done_target {
            let remaining = end - state.lambda;
            if remaining.abs() <= 1e-12 * end.abs().max(1.0) {
                break;
            }
            if size.abs() > remaining.abs() {
                size = remaining;
            }
        }
        if let Control::Displacement { delta, .. } = &params.control {
            let remaining = delta - travelled;
            if remaining.abs() <= 1e-12 * delta.abs() {
                break;
            }
            if size.abs() > remaining.abs() {
                size = remaining;
            }
        }
        let inc = match &params.control {
            Control::Load { .. } => Increment::Load(size),
            Control::Displacement { node, dof, .. } => {
                let Slot::Free(eq) = s.system.dofs.slots[*node][dof.index()] else {
                    unreachable!()
                };
                Increment::Displacement { eq, delta: size }
            }
            Control::ArcLength {
                direction,
                initial_increment,
                lambda_end,
                ..
            } => {
                if arc_ds.is_none() {
                    // First step: the arc length that gives the requested load-factor increment.
                    if !s.fresh {
                        s.assemble(state);
                    }
                    let (_, dq_b) = match s.solve_pair() {
                        Ok(v) => v,
                        Err(e) => {
                            path.error = Some(e);
                            break 'steps;
                        }
                    };
                    arc_ds = Some(initial_increment * (s.dot_w(&dq_b, &dq_b) + s.c_lambda).sqrt());
                    size = arc_ds.expect("set");
                }
                // Without a previous increment (first step, or after a jump) head for lambda_end.
                let towards = (lambda_end - state.lambda).signum();
                Increment::Arc {
                    ds: size.abs(),
                    direction: if towards == 0.0 { *direction } else { towards },
                }
            }
        };
        let saved = state.clone();
        match s.increment(state, inc) {
            Ok(out) => {
                // A limit point of the load factor: jump to the stable equilibrium beyond it.
                if let (true, Control::ArcLength { lambda_end, .. }) = (params.jump_at_limit_points, &params.control) {
                    let travel = (lambda_end - saved.lambda).signum();
                    if (state.lambda - saved.lambda) * travel < 0.0 && last_dlambda.is_some() {
                        let mut offset = last_dlambda.map_or(1e-3, |dl| 0.25 * dl.abs()).max(1e-6);
                        let mut jumped = false;
                        for _ in 0..8 {
                            *state = saved.clone();
                            match s.relax(state, saved.lambda + travel * offset) {
                                Ok(_) => {
                                    if s.distance(state, &saved) > 0.5 * size.abs() {
                                        jumped = true;
                                        break;
                                    }
                                    // Still on the same branch: the limit lies further on.
                                    offset *= 2.0;
                                }
                                Err(e) => {
                                    *state = saved.clone();
                                    path.error = Some(e);
                                    break 'steps;
                                }
                            }
                        }
                        if !jumped {
                            *state = saved.clone();
                            path.error = Some(Error::NotConverged {
                                lambda: state.lambda,
                                iterations: 0,
                                residual: f64::NAN,
                                detail: "no stable equilibrium found beyond the limit point".into(),
                            });
                            break 'steps;
                        }
                        s.invalidate();
                        s.assemble(state);
                        let relaxed = Outcome {
                            iterations: 0,
                            residual: 0.0,
                            dq: Vec::new(),
                            dlambda: 0.0,
                        };
                        match s.record(state, &relaxed) {
                            Ok(mut st) => {
                                st.jump = true;
                                s.stats.steps += 1;
                                let keep_going = progress(&st, &s.stats);
                                path.steps.push(st);
                                if !keep_going {
                                    path.cancelled = true;
                                    break 'steps;
                                }
                            }
                            Err(e) => {
                                path.error = Some(e);
                                break 'steps;
                            }
                        }
                        s.previous = None;
                        cutbacks = 0;
                        continue 'steps;
                    }
                }
                // Arc-length: do not overshoot the final load factor; finish with a load step.
                if let Control::ArcLength { lambda_end, .. } = &params.control {
                    let start_l = saved.lambda;
                    let crossed = (start_l - lambda_end) * (state.lambda - lambda_end) < 0.0 && last_dlambda.is_some();
                    if crossed {
                        let mut trial = saved.clone();
                        s.invalidate();
                        if let Ok(o2) = s.increment(&mut trial, Increment::Load(lambda_end - start_l)) {
                            *state = trial;
                            let step = match s.record(state, &o2) {
                                Ok(st) => st,
                                Err(e) => {
                                    path.error = Some(e);
                                    break;
                                }
                            };
                            s.stats.steps += 1;
                            path.steps.push(step);
                            let _ = progress(path.steps.last().expect("pushed"), &s.stats);
                            break;
                        }
                        // The final load step failed: retry the crossing with a shorter arc.
                        *state = saved;
                        s.invalidate();
                        cutbacks += 1;
                        s.stats.cutbacks += 1;
                        if cutbacks > params.max_cutbacks {
                            path.error = Some(Error::NotConverged {
                                lambda: state.lambda,
                                iterations: 0,
                                residual: f64::NAN,
                                detail: format!("could not land on the final load factor {lambda_end}"),
                            });
                            break;
                        }
                        size *= 0.5;
                        continue 'steps;
                    }
                }
                cutbacks = 0;
                s.strict_turns = true;
                s.tangent_predictor = true;
                s.path_force = s
                    .path_force
                    .max((state.lambda.abs() * s.force_norm(&s.asm.f_ext)).max(s.reaction_norm()));
                let step = match s.record(state, &out) {
                    Ok(st) => st,
                    Err(e) => {
                        path.error = Some(e);
                        break;
                    }
                };
                s.stats.steps += 1;
                let keep_going = progress(&step, &s.stats);
                path.steps.push(step);
                if let Control::Displacement { .. } = &params.control {
                    travelled += size;
                }
                // Adapt the increment to the Newton effort.
                let ratio = (params.target_iterations as f64 / out.iterations.max(1) as f64)
                    .sqrt()
                    .clamp(0.5, 2.0);
                match &params.control {
                    Control::ArcLength {
                        max_increment_factor,
                        lambda_end,
                        ..
                    } => {
                        let ds0 = arc_ds.expect("set on the first step");
                        size = (size.abs() * ratio).min(ds0 * max_increment_factor);
                        let reached = (state.lambda - lambda_end) * (saved.lambda - lambda_end) <= 0.0;
                        if reached && last_dlambda.is_some() {
                            break;
                        }
                    }
                    _ => size = size.signum() * (size.abs() * ratio).min(initial_size),
                }
                last_dlambda = Some(out.dlambda);
                s.previous = Some((out.dq, out.dlambda));
                if !keep_going {
                    path.cancelled = true;
                    break;
                }
                steps_left = steps_left.saturating_sub(1);
            }
            Err(err) => {
                *state = saved;
                s.invalidate();
                cutbacks += 1;
                s.stats.cutbacks += 1;
                if cutbacks > params.max_cutbacks {
                    let detail = format!("increment cut back {} times; last failure: {err}", params.max_cutbacks);
                    let (iterations, residual) = match err {
                        Error::NotConverged {
                            iterations, residual, ..
                        } => (iterations, residual),
                        _ => (0, f64::NAN),
                    };
                    path.error = Some(Error::NotConverged {
                        lambda: state.lambda,
                        iterations,
                        residual,
                        detail,
                    });
                    break;
                }
                size *= 0.5;
                s.strict_turns = cutbacks < params.max_cutbacks / 2;
                s.tangent_predictor = false;
                log::debug!("increment failed at lambda = {}: {err}; cutting back", state.lambda);
            }
        }
    }
    if let Control::ArcLength {
        lambda_end, max_steps, ..
    } = &params.control
    {
        let short = (state.lambda - lambda_end).abs() > 1e-9 * lambda_end.abs().max(1.0);
        if path.error.is_none() && !path.cancelled && short {
            path.error = Some(Error::NotConverged {
                lambda: state.lambda,
                iterations: 0,
                residual: f64::NAN,
                detail: format!("{max_steps} arc-length steps used before the load factor reached {lambda_end}"),
            });
        }
    }
    s.stats.refinement_sweeps = s.linear.refinement_sweeps;
    s.stats.lu_fallbacks = s.linear.lu_fallbacks;
    s.stats.wall_s = start.elapsed().as_secs_f64();
    path.stats = s.stats;
    Ok(path)
}

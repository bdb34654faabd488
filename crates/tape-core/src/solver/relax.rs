//! The stable path of a slowly driven test: jumps at limit points and branch switches at
//! bifurcations.
//!
//! Where a path driven by a load factor reaches a limit and turns back, a slow test driven by the
//! same loads or motions snaps to a stable equilibrium beyond the limit. Where the tangent loses
//! its positive definiteness while the load factor keeps going (a bifurcation: a pivot of the
//! LDL^T changes sign without a limit point), the test leaves the now unstable path along the
//! critical mode. Both stable equilibria are found by pseudo-transient continuation: each
//! pseudo-time step solves `r(q) + C (q - q_k) = 0` with `C = beta diag|K|`, `beta` large enough
//! that `K + C` is positive definite, so every step descends the potential (an implicit gradient
//! flow); `beta` shrinks as steps succeed, ending in plain Newton at a stable equilibrium.
//!
//! At a bifurcation, the last stable state before it is located by bisection along the path (on
//! hyperplanes across the chord, as in [`super::events`]), the critical mode is the eigenvector of
//! the tangent's eigenvalue nearest zero there (inverse iteration with the LDL^T of the symmetric
//! part), and the state just past the bifurcation, pushed both ways along the mode, is relaxed: of
//! the stable equilibria reached, the one of lowest potential energy is the branch followed (the
//! two are mirror images when the bifurcation is symmetric; the sign of the mode then decides).

use super::events::{discount_neutral, Found};
use super::statics::Driver;
use super::{Event, StaticStep};
use crate::eigen::dot;
use crate::error::{Clock, Error, Result};
use crate::state::State;

/// An eigenvalue above `-NEUTRAL` times the largest diagonal entry of the tangent is zero to
/// round-off: a hundred ulps (the instabilities met past the equal-sense bifurcations of the tape
/// measure -4e-14 and beyond, its neutral sliding modes -7e-16).
const NEUTRAL: f64 = 100.0 * f64::EPSILON;

/// Relative potential energy an unstable state must lose, relaxed from a push along its critical
/// mode, to count as left. On the 2 mm equal-sense tape: the snaps release 1.3e-4 (the heel) to
/// 0.14 (the fold); a fold slid along its neutral mode changes it by 1e-12 to 5e-8, and by up to
/// 1.2e-6 where it slips from one element to the next.
const NEUTRAL_ENERGY: f64 = 1e-5;

/// Largest growth of the load-factor offset between two trials of a jump (see [`Driver::jump`]).
const JUMP_GROWTH: f64 = 16.0;

/// Relaxations past a limit point that may fail, each followed by one further past it, before the
/// jump is given up (see [`Driver::jump`]).
const MAX_JUMP_FAILURES: usize = 1;

/// Largest translation of a trial push along a critical mode, as a fraction of the model's
/// characteristic length (half its bounding box's diagonal: 1 mm on the 100 mm tape).
const PUSH: f64 = 0.02;

/// Trial pushes along a critical mode, each [`PUSH_SHRINK`] times shorter than the last, while the
/// relaxation from the pushed state fails (see [`Driver::pushed_relaxed`]).
const PUSH_TRIES: usize = 3;

/// Ratio of two successive trial pushes.
const PUSH_SHRINK: f64 = 4.0;

/// The outcome of a branch switch at a bifurcation.
pub(super) struct Switch {
    /// The last stable state located before the bifurcation, recorded with its event.
    pub critical: Option<(State, StaticStep)>,
    /// Potential energy of the stable state reached on the chosen branch (the driver's state on
    /// return) \[J\].
    pub energy: f64,
}

impl Driver<'_> {
    /// From the converged `saved` state before a limit point, finds a stable equilibrium a little
    /// beyond it (load factor `saved.t + travel * offset`, the offset grown until the state
    /// leaves `saved`'s branch by more than half the arc length `ds`, and once by
    /// [`JUMP_GROWTH`] after a relaxation that finds nothing); `state` ends there, with its pieces
    /// assembled.
    ///
    /// # Errors
    /// [`Error::NotConverged`] if no stable equilibrium is found.
    pub fn jump(
        &mut self,
        state: &mut State,
        saved: &State,
        travel: f64,
        last_dlambda: Option<f64>,
        ds: f64,
    ) -> Result<()> {
        let mut offset = last_dlambda.map_or(1e-3, |dl| 0.25 * dl.abs()).max(1e-6);
        let mut failures = 0;
        for _ in 0..8 {
            *state = saved.clone();
            match self.relax(state, saved.t + travel * offset, None) {
                Ok(()) => {}
                // Just past a limit point the relaxation can converge onto an unstable
                // equilibrium (the set-up's push, 3.8e-5 in load factor past its buckle);
                // further past it the flow passes it by.
                Err(Error::NotConverged { .. }) if failures < MAX_JUMP_FAILURES => {
                    log::debug!(
                        "jump from t = {}: no relaxation at offset {offset:.3e}, trying further",
                        saved.t
                    );
                    failures += 1;
                    offset *= JUMP_GROWTH;
                    continue;
                }
                Err(e) => {
                    *state = saved.clone();
                    return Err(e);
                }
            }
            let distance = self.distance(state, saved);
            log::trace!(
                "jump from t = {}: offset {offset:.3e}, distance {distance:.3e}, ds {ds:.3e}",
                saved.t
            );
            if distance > 0.5 * ds {
                self.invalidate();
                self.assemble(state);
                return Ok(());
            }
            // Still on the same branch: the limit lies further on. Along a branch the relaxed
            // state moves in proportion to the offset, so the next offset aims at 0.75 ds (a
            // doubling from an offset set by a crawling step's tiny increment could stop far
            // short of it: measured on the equal-sense tape's plateau, 1e-6 doubled seven times).
            offset *= (0.75 * ds / distance).clamp(2.0, JUMP_GROWTH);
        }
        *state = saved.clone();
        Err(Error::NotConverged {
            step: None,
            t: state.t,
            clock: Clock::LoadFactor,
            iterations: 0,
            residual: f64::NAN,
            detail: "no stable equilibrium found beyond the limit point".into(),
        })
    }

    /// Whether the unstable equilibrium `state` (its tangent factorised) is one a slow test leaves:
    /// pushed along the critical mode (see [`Driver::push_amount`]) and relaxed, the state must go
    /// at least half the push away and lose more than [`NEUTRAL_ENERGY`] of its potential energy. A
    /// neutral mode (a fold free to slide) or a pivot at round-off level fails the test. `state` is
    /// unchanged; the driver's pieces are those of the trial (assemble again).
    ///
    /// # Errors
    /// A failure of the linear algebra.
    pub fn leaves(&mut self, state: &State) -> Result<bool> {
        let mode = self.inverse_iteration(&[])?;
        // A neutral mode nearest zero (a balanced body beside a part that buckles) hides any
        // further negative pivot's instability: that one's mode, the next nearest zero, is tried
        // too. Found now, while the state's tangent is factorised.
        let beyond = if self.system.linear.negative_eigenvalues()? >= 2 && self.is_neutral(&mode) {
            Some(self.inverse_iteration(std::slice::from_ref(&mode))?)
        } else {
            None
        };
        let energy = self.asm.energy + self.asm.gravity_energy;
        // The flow descends the potential: once below the level that counts as left, it stays
        // below, and the rest of the way to the stable equilibrium (three quarters of the
        // relaxation where the equal-sense tape leaves its path) tells nothing more.
        let left = energy - NEUTRAL_ENERGY * energy.abs();
        for mode in std::iter::once(mode).chain(beyond) {
            let push = self.push_amount(&mode);
            let relaxed = self
                .pushed_relaxed(state, &mode, push, state.t, Some(left))
                .map(|_| self.asm.energy + self.asm.gravity_energy);
            self.invalidate();
            if relaxed.is_some_and(|e| e < left) {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// A stable equilibrium at load factor `lambda`, relaxed from `from`; `state` ends there, with
    /// its pieces assembled.
    ///
    /// # Errors
    /// [`Error::NotConverged`] if no stable equilibrium is found (`state` is then `from`).
    pub fn relax_at(&mut self, state: &mut State, from: &State, lambda: f64) -> Result<()> {
        *state = from.clone();
        if let Err(e) = self.relax(state, lambda, None) {
            *state = from.clone();
            return Err(e);
        }
        self.invalidate();
        self.assemble(state);
        Ok(())
    }

    /// Between the stable converged state `stable` and the unstable one `unstable` reached from it
    /// without a limit point (and left, see [`Driver::leaves`]), locates the bifurcation, and moves
    /// `state` to a stable equilibrium on the branch leaving it (see the module notes). With
    /// `neutral` (the path has a neutral mode from its start) the states of the location leave
    /// that mode out of their counts, as the path's own states do.
    ///
    /// # Errors
    /// A failure of the linear algebra, or no stable equilibrium found either way.
    pub fn switch_branch(
        &mut self,
        state: &mut State,
        stable: &State,
        unstable: &State,
        neutral: bool,
    ) -> Result<Switch> {
        // The bifurcation, by bisection along the path between the stable and unstable states.
        // Near it the tangent is nearly singular along the critical mode, which the hyperplane
        // does not fix: a solve that fails there counts as past it.
        let chord = self.difference(stable, unstable);
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut last_stable: Option<Found> = None;
        let t_at = |s: f64| stable.t + s * chord.1;
        // Load factor at `hi`: that of the state found there (the path bends near the
        // bifurcation, so it differs from the chord's), else the chord's.
        let mut t_hi = unstable.t;
        for _ in 0..16 {
            if (t_hi - t_at(lo)).abs() < self.params.event_tolerance {
                break;
            }
            let mid = 0.5 * (lo + hi);
            let mut found = self.on_plane(stable, &chord, mid, None);
            if let (true, Some(f)) = (neutral, found.as_mut()) {
                discount_neutral(self, f)?;
            }
            match found {
                Some(found) if found.step.negative_eigenvalues == Some(0) => {
                    lo = mid;
                    last_stable = Some(found);
                }
                found => {
                    hi = mid;
                    t_hi = found.map_or_else(|| t_at(mid), |f| f.state.t);
                }
            }
        }
        // From the last stable state, both ways along the mode, just past the bifurcation: the
        // stable equilibrium of lowest potential energy is the branch followed. Failed solves may
        // have put `hi` before the bifurcation: if both ways relax back onto the path, go further
        // (beyond the unstable state too, when the stable branch lies past a snap).
        let start = last_stable
            .as_ref()
            .map_or_else(|| stable.clone(), |f| f.state.clone());
        let mode = self.critical_mode(&start)?;
        let push = self.push_amount(&mode);
        let mut best: Option<(State, f64)> = None;
        // Past a limit point the path comes back in load factor: the switch is never behind the
        // last stable state (it is then the jump of a limit point).
        let t_lo = last_stable.as_ref().map_or(stable.t, |f| f.state.t);
        let t_hi = if chord.1 >= 0.0 { t_hi.max(t_lo) } else { t_hi.min(t_lo) };
        let mut t_switch = t_hi;
        for s_switch in [hi, 0.5 * (hi + 1.0), 1.0, 2.0, 4.0, 8.0] {
            if s_switch > hi {
                // Further along, never behind the state found past the bifurcation.
                let t = t_at(s_switch);
                t_switch = if chord.1 >= 0.0 { t.max(t_hi) } else { t.min(t_hi) };
            }
            for sign in [1.0, -1.0] {
                let Some(trial) = self.pushed_relaxed(&start, &mode, sign * push, t_switch, None) else {
                    continue;
                };
                let energy = self.asm.energy + self.asm.gravity_energy;
                if best.as_ref().is_none_or(|(_, e)| energy < *e) {
                    best = Some((trial, energy));
                }
            }
            if best.is_some() {
                break;
            }
        }
        let Some((switched, energy)) = best else {
            return Err(Error::NotConverged {
                step: None,
                t: t_switch,
                clock: Clock::LoadFactor,
                iterations: 0,
                residual: f64::NAN,
                detail: "no stable equilibrium found along the critical mode of a bifurcation".into(),
            });
        };
        let critical = last_stable.map(|mut f| {
            f.step.event = Some(Event::Bifurcation);
            (f.state, f.step)
        });
        *state = switched;
        self.invalidate();
        self.assemble(state);
        Ok(Switch { critical, energy })
    }

    /// The eigenvector of the tangent's eigenvalue nearest zero at `at` (inverse iteration with
    /// the LDL^T of the symmetric part), of unit weighted norm. At a stable state with a negative
    /// pivot (a neutral mode, left out of its count) a neutral mode nearest zero is passed over
    /// for the next: the mode that turns critical is the one beside it.
    fn critical_mode(&mut self, at: &State) -> Result<Vec<f64>> {
        self.invalidate();
        self.assemble(at);
        self.factorise()?;
        let mode = self.inverse_iteration(&[])?;
        if self.system.linear.negative_eigenvalues()? >= 1 && self.is_neutral(&mode) {
            return self.inverse_iteration(std::slice::from_ref(&mode));
        }
        Ok(mode)
    }

    /// Whether `mode`'s Rayleigh quotient is zero to round-off (see [`NEUTRAL`]), of either sign.
    fn is_neutral(&self, mode: &[f64]) -> bool {
        self.relative_rayleigh(mode).abs() <= NEUTRAL
    }

    /// Inverse iteration with the factorised tangent's symmetric part, orthogonal to the
    /// eigenvectors `found` (of that part; the Euclidean product): the eigenvector of the
    /// eigenvalue nearest zero but theirs.
    fn inverse_iteration(&mut self, found: &[Vec<f64>]) -> Result<Vec<f64>> {
        let n = self.system.n_free();
        // A deterministic start with components along every DOF.
        #[allow(clippy::cast_precision_loss)]
        let mut mode: Vec<f64> = (0..n)
            .map(|i| ((i as f64) * 0.618_033_988_749_895).fract() - 0.5)
            .collect();
        // Removed before each solve and after it: a solve with the nearly singular tangent
        // amplifies the round-off left along a mode of an eigenvalue at round-off level by as
        // much as its inverse.
        let deflate = |v: &mut [f64]| {
            for m in found {
                let c = dot(v, m) / dot(m, m);
                v.iter_mut().zip(m).for_each(|(x, y)| *x -= c * y);
            }
        };
        for _ in 0..30 {
            deflate(&mut mode);
            self.system
                .linear
                .solve_symmetric_part_in_place(&mut mode)?;
            deflate(&mut mode);
            let norm = self.dot_w(&mode, &mode).sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                return Err(Error::Factorisation(
                    "inverse iteration for the critical mode failed".into(),
                ));
            }
            for v in &mut mode {
                *v /= norm;
            }
        }
        Ok(mode)
    }

    /// Negative eigenvalues of the factorised tangent of the current state, not counting one at
    /// round-off level (a neutral mode, see [`NEUTRAL`]). Used to tell instabilities a state can
    /// leave from neutral modes; the stability recorded on paths is the plain count (the
    /// eigenvalues of bending-dominated unstable branches of thin shells are themselves a few
    /// ulps of the membrane stiffness, so no such threshold separates them from neutral modes).
    ///
    /// # Errors
    /// No factorisation, or a failed solve.
    pub fn negative_eigenvalues(&mut self) -> Result<usize> {
        self.factorise()?;
        let count = self.system.linear.negative_eigenvalues()?;
        if count != 1 {
            return Ok(count);
        }
        let mode = self.inverse_iteration(&[])?;
        Ok(usize::from(self.relative_rayleigh(&mode) <= -NEUTRAL))
    }

    /// Rayleigh quotient of the current tangent for `mode`, relative to the largest diagonal entry.
    fn relative_rayleigh(&self, mode: &[f64]) -> f64 {
        let mut km = vec![0.0; mode.len()];
        self.system
            .pattern_ff
            .mul_add(&self.asm.k_ff, mode, &mut km);
        let num = dot(mode, &km);
        let den = dot(mode, mode);
        let diag = (0..mode.len())
            .filter_map(|i| self.system.pattern_ff.find(i, i))
            .map(|p| self.asm.k_ff[p].abs())
            .fold(0.0, f64::max);
        num / den / diag
    }

    /// How far to push along the unit `mode` (weighted norm) to try whether a state leaves it: so
    /// far that the largest translation is [`PUSH`] of the model's characteristic length. Just past
    /// a bifurcation the potential is flat along the mode to second order: a push scaled on the
    /// path's steps (which close in on it) would stay within the relaxation's tolerance.
    fn push_amount(&self, mode: &[f64]) -> f64 {
        let lc = self.system.char_length;
        let (mut translation, mut rotation) = (0.0, 0.0);
        for ((_, dof), v) in self.system.dofs.free_dofs.iter().zip(mode) {
            if dof.is_rotation() {
                rotation = v.abs().max(rotation);
            } else {
                translation = v.abs().max(translation);
            }
        }
        // A mode of rotations alone (a body turning about a held point) has translations of
        // round-off, by which the push would be astronomical: it is pushed by its rotations.
        let largest = translation.max(1e-3 * rotation * lc);
        if largest > 0.0 {
            PUSH * lc / largest
        } else {
            PUSH * lc
        }
    }

    /// `from` pushed by `amount` (weighted norm, signed) along the unit `mode` and relaxed at load
    /// factor `lambda` (until below the energy `below`, if given: see [`Self::relax`]), its pieces
    /// assembled; `None` unless it went at least half the push away. A relaxation that fails is
    /// tried again from a push [`PUSH_SHRINK`] times shorter, [`PUSH_TRIES`] pushes in all: where
    /// the branch left lies nearer than the push (a strip pushed in to 1.5 times its Euler
    /// shortening buckles by 1.1 mm, the push is 2 mm), the pushed state is stretched beyond it
    /// (its energy rose from 0.050 to 0.070 J) and the flow from there found no equilibrium (in
    /// 3600 iterations, a second on that strip). The push that relaxed is where the next trial
    /// starts on the path (`push_factor`), so that failure is paid once.
    fn pushed_relaxed(
        &mut self,
        from: &State,
        mode: &[f64],
        amount: f64,
        lambda: f64,
        below: Option<f64>,
    ) -> Option<State> {
        let mut factor = self.push_factor;
        for _ in 0..PUSH_TRIES {
            let mut trial = from.clone();
            self.push_along(&mut trial, mode, factor * amount);
            if self.relax(&mut trial, lambda, below).is_ok() {
                self.push_factor = factor;
                return (self.distance(&trial, from) >= 0.5 * (factor * amount).abs()).then_some(trial);
            }
            factor /= PUSH_SHRINK;
        }
        None
    }

    /// Moves `state` by `amount` (weighted norm) along the unit `mode`, at fixed load factor.
    fn push_along(&self, state: &mut State, mode: &[f64], amount: f64) {
        let push: Vec<f64> = mode.iter().map(|v| amount * v).collect();
        self.system.update(state, &push, 0.0);
    }

    /// Moves the load factor to `lambda` and relaxes `state` to a stable equilibrium there, or,
    /// with `below`, until a pseudo-step ends at a potential energy below it \[J\] (`state` is then
    /// on the way, with its pieces assembled).
    ///
    /// # Errors
    /// [`Error::NotConverged`] if the pseudo-time steps run out, the shift grows beyond any use,
    /// or the flow converges onto an unstable equilibrium; a failure of the linear algebra.
    fn relax(&mut self, state: &mut State, lambda: f64, below: Option<f64>) -> Result<()> {
        const MAX_STEPS: usize = 400;
        let n = self.system.n_free();
        let zero = vec![0.0; n];
        self.system.update(state, &zero, lambda - state.t);
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
            let (ok, rr) = self.converged(None);
            log::trace!("relaxation step {step}: beta {beta:.1e}, residual {rr:.3e}");
            if below.is_some_and(|e| self.asm.energy + self.asm.gravity_energy < e) {
                return Ok(());
            }
            if ok && beta <= 1e-6 {
                // A negative eigenvalue at round-off level is a neutral mode (a fold free to slide
                // along a uniform tape: measured -7e-16 of the largest diagonal entry), not an
                // instability the flow can leave: the state is as stable as it gets.
                if self.negative_eigenvalues()? == 0 {
                    return Ok(());
                }
                // An unstable equilibrium: with the shift this small the steps are Newton's,
                // which converge onto saddles too, and no flow leaves one (its gradient is
                // zero). Going on with a larger shift came back to it every few steps until the
                // steps ran out (measured past the set-up's buckles: 70 to 80 returns in 400
                // steps, every one onto the same saddle): the callers' own remedies (a jump
                // further past its limit, a shorter push) cost less.
                return Err(Error::NotConverged {
                    step: None,
                    t: state.t,
                    clock: Clock::LoadFactor,
                    iterations: step,
                    residual: rr,
                    detail: "relaxation converged onto an unstable equilibrium".into(),
                });
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
                let mut r = self.r.clone();
                for (i, &p) in diag.iter().enumerate() {
                    // A negative diagonal entry (the gravity stiffness of a balanced body) is
                    // lifted to its magnitude first: no beta of the shift alone makes it positive
                    // short of beta = 1, at which the flow over the rest crawls.
                    let kii = self.asm.k_ff[p];
                    let c = beta * kii.abs().max(1e-12) + 2.0 * (-kii).max(0.0);
                    k[p] += c;
                    r[i] += c * acc[i];
                }
                let res = self.force_norm(&r);
                if it > 0 && res <= self.conv.tol_force * self.reference_force().max(self.conv.round_off) {
                    success = true;
                    break;
                }
                let t = std::time::Instant::now();
                self.system.linear.factorize(&k)?;
                self.stats.factorisations += 1;
                self.stats.factorisation_s += t.elapsed().as_secs_f64();
                self.factorised = false;
                if self.system.linear.negative_eigenvalues().unwrap_or(1) > 0 {
                    // K + C must be positive definite for a descent step.
                    break;
                }
                let mut dq: Vec<f64> = r.iter().map(|v| -v).collect();
                self.system.linear.solve_in_place(&mut dq)?;
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
            step: None,
            t: state.t,
            clock: Clock::LoadFactor,
            iterations: MAX_STEPS,
            residual: self.force_norm(&self.r),
            detail: "relaxation past a limit point found no stable equilibrium".into(),
        })
    }
}

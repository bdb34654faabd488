//! Jumps at limit points: where a path driven by a load factor reaches a limit and turns back, a
//! slow test driven by the same loads or motions snaps to a stable equilibrium beyond the limit.
//! That equilibrium is found by pseudo-transient continuation: each pseudo-time step solves
//! `r(q) + C (q - q_k) = 0` with `C = beta diag|K|`, `beta` large enough that `K + C` is positive
//! definite, so every step descends the potential (an implicit gradient flow); `beta` shrinks as
//! steps succeed, ending in plain Newton at a stable equilibrium.

use super::statics::Driver;
use crate::error::{Error, Result};
use crate::state::State;

impl Driver<'_> {
    /// From the converged `saved` state before a limit point, finds a stable equilibrium a little
    /// beyond it (load factor `saved.t + travel * offset`, the offset doubled until the state
    /// leaves `saved`'s branch by more than half the arc length `ds`); `state` ends there, with
    /// its pieces assembled.
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
        for _ in 0..8 {
            *state = saved.clone();
            self.relax(state, saved.t + travel * offset)?;
            if self.distance(state, saved) > 0.5 * ds {
                self.invalidate();
                self.assemble(state);
                return Ok(());
            }
            // Still on the same branch: the limit lies further on.
            offset *= 2.0;
        }
        *state = saved.clone();
        Err(Error::NotConverged {
            step: None,
            t: state.t,
            iterations: 0,
            residual: f64::NAN,
            detail: "no stable equilibrium found beyond the limit point".into(),
        })
    }

    /// Moves the load factor to `lambda` and relaxes `state` to a stable equilibrium there.
    /// Returns the pseudo-steps used.
    fn relax(&mut self, state: &mut State, lambda: f64) -> Result<usize> {
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
            if ok && beta <= 1e-6 {
                self.factorise()?;
                if self.system.linear.negative_eigenvalues()? == 0 {
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
                let mut r = self.r.clone();
                for (i, &p) in diag.iter().enumerate() {
                    let c = beta * self.asm.k_ff[p].abs().max(1e-12);
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
            iterations: MAX_STEPS,
            residual: self.force_norm(&self.r),
            detail: "relaxation past a limit point found no stable equilibrium".into(),
        })
    }
}

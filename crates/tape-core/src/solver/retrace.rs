//! Detection of an arc-length path that comes back onto a stretch it has already followed.
//!
//! An equilibrium path is a curve in the space of configurations and load factor; it cannot pass
//! twice through the same state unless it retraces itself (the continuation turned back, seen on
//! a shallow roof pulled far past a limit point, which then went back through the origin and up
//! the other way until the step limit) or closes a loop. Either way continuing would only repeat
//! the shapes already recorded. So the converged states are remembered as points `z = u` (the
//! nodal displacements \[m\]: the shape), and a state is found to be on the old path when it lies
//! near a segment between two remembered states that is far behind it along the path, and its own
//! increment is parallel (a loop) or antiparallel (a retrace) to that segment. Rotations are left
//! out: the nodes' rotations about their normals (drilling) are nearly free, and on that roof the
//! path came back through the same shapes with its nodes turned more and more about them (2 rad
//! back at zero load), a neighbouring branch in the space of all DOFs, the same one to the user.
//! The tests:
//!
//! * near: within a quarter of the longer of the two steps (two chords of the same curve, each
//!   bending by at most 60 degrees per step, are closer than that);
//! * far behind: more than twice the two steps' lengths back along the path (a sharp but genuine
//!   limit point does not match: its neighbours are recent);
//! * parallel: `|cos| > 0.8` between the increment and the segment;
//! * the same stability: where the number of negative eigenvalues of the tangent is known, the
//!   state's must be that of one end of the segment (on a deep tape section the unstable branch
//!   beyond the snap runs back beside the loading branch, nearer to it than a step, its fold only
//!   beginning to form; the count tells the two apart, the distance does not);
//! * confirmed: two successive states must match.
//!
//! Memory: the points are thinned (every other one dropped, the first kept) whenever they hold
//! more than [`MAX_FLOATS`] numbers, so a large model keeps only a few (the path is then still
//! found when it comes back near the origin or another kept state).

use crate::state::State;

/// Largest number of floats kept (32 MB).
const MAX_FLOATS: usize = 4 << 20;

struct Mark {
    z: Vec<f64>,
    norm: f64,
    /// Load factor.
    t: f64,
    /// Position along the path (sum of the step lengths in the `z` metric).
    arc: f64,
    /// Number of the converged increment that reached it (0: the start).
    increment: usize,
    /// First state after a jump: no segment leads to it.
    piece_start: bool,
    /// Negative eigenvalues of the tangent there, if counted.
    negative: Option<usize>,
}

/// The part of the path already followed, and how it was met again.
pub(super) struct PathMemory {
    marks: Vec<Mark>,
    last: Option<Mark>,
    /// The previous state matched the old path.
    pending: bool,
    increments: usize,
}

/// The path met an old stretch of itself.
pub(super) struct Return {
    /// Load factor of the old state met.
    pub t_old: f64,
    /// Increment that had reached it.
    pub increment_old: usize,
    /// Going back along the old stretch (else in the same sense: a loop).
    pub reversed: bool,
    /// Load factor farthest from the start on the way (where a retrace turned back).
    pub t_turn: f64,
}

impl PathMemory {
    pub fn new() -> Self {
        Self {
            marks: Vec::new(),
            last: None,
            pending: false,
            increments: 0,
        }
    }

    fn point(state: &State, reference: &State) -> Vec<f64> {
        (0..state.x.len())
            .flat_map(|i| {
                state
                    .displacement(reference, i)
                    .into_iter()
                    .copied()
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// A state reached by a jump or a relaxation (with its stability count, if known): the path
    /// restarts there.
    pub fn restart(&mut self, state: &State, reference: &State, negative: Option<usize>) {
        self.pending = false;
        self.push(state, reference, true, negative);
    }

    /// Records a converged state of the path (with its stability count, if known); `Some` if it
    /// confirms that the path is on a stretch followed before.
    pub fn visit(&mut self, state: &State, reference: &State, negative: Option<usize>) -> Option<Return> {
        self.increments += 1;
        let found = self.push(state, reference, false, negative);
        let confirmed = found.is_some() && self.pending;
        self.pending = found.is_some();
        if confirmed {
            found
        } else {
            None
        }
    }

    /// Appends `state`; returns what it meets of the old path (if anything).
    fn push(&mut self, state: &State, reference: &State, piece_start: bool, negative: Option<usize>) -> Option<Return> {
        let z = Self::point(state, reference);
        let norm = z.iter().map(|v| v * v).sum::<f64>().sqrt();
        let (arc, found) = match (&self.last, piece_start) {
            (Some(last), false) => {
                let step: Vec<f64> = z.iter().zip(&last.z).map(|(a, b)| a - b).collect();
                let len = step.iter().map(|v| v * v).sum::<f64>().sqrt();
                let arc = last.arc + len;
                (arc, self.meet(&z, norm, &step, len, arc, state.t, negative))
            }
            (Some(last), true) => (last.arc, None),
            (None, _) => (0.0, None),
        };
        let mark = Mark {
            z,
            norm,
            t: state.t,
            arc,
            increment: self.increments,
            piece_start,
            negative,
        };
        if let Some(last) = self.last.replace(mark) {
            self.marks.push(last);
        }
        let floats: usize = self.marks.iter().map(|m| m.z.len()).sum();
        if floats > MAX_FLOATS && self.marks.len() > 2 {
            // Keep the first (the start of the path) and every other one after it.
            let mut k = 0;
            self.marks.retain(|_| {
                k += 1;
                k % 2 == 1
            });
        }
        found
    }

    /// The old segment that the step `step` (of length `len`) to `z` lies on, if any.
    #[allow(clippy::too_many_arguments)]
    fn meet(
        &self,
        z: &[f64],
        norm: f64,
        step: &[f64],
        len: f64,
        arc: f64,
        t: f64,
        negative: Option<usize>,
    ) -> Option<Return> {
        if len == 0.0 {
            return None;
        }
        for (k, pair) in self.marks.windows(2).enumerate() {
            let (a, b) = (&pair[0], &pair[1]);
            if b.piece_start {
                continue;
            }
            let seg_len = (b.arc - a.arc).max(0.0);
            let near = 0.25 * len.max(seg_len);
            if arc - b.arc <= 2.0 * (len + seg_len) {
                continue;
            }
            if let (Some(n), Some(na), Some(nb)) = (negative, a.negative, b.negative) {
                if n != na && n != nb {
                    continue;
                }
            }
            // Cheap bounds first: the distance to the segment is at least the distance of the
            // norms to the norm range of its ends.
            if norm < a.norm.min(b.norm) - near || norm > a.norm.max(b.norm) + near {
                continue;
            }
            let ab: Vec<f64> = b.z.iter().zip(&a.z).map(|(p, q)| p - q).collect();
            let ab2: f64 = ab.iter().map(|v| v * v).sum();
            if ab2 == 0.0 {
                continue;
            }
            let az_ab: f64 = z
                .iter()
                .zip(&a.z)
                .zip(&ab)
                .map(|((p, q), d)| (p - q) * d)
                .sum();
            let s = (az_ab / ab2).clamp(0.0, 1.0);
            let d2: f64 = z
                .iter()
                .zip(&a.z)
                .zip(&ab)
                .map(|((p, q), d)| {
                    let r = p - q - s * d;
                    r * r
                })
                .sum();
            let cos = step.iter().zip(&ab).map(|(p, q)| p * q).sum::<f64>() / (len * ab2.sqrt());
            if d2.sqrt() > near {
                continue;
            }
            if cos.abs() < 0.8 {
                continue;
            }
            let start = self.marks[0].t;
            let t_turn = self.marks[k..]
                .iter()
                .map(|m| m.t)
                .chain([t])
                .fold(start, |acc, v| {
                    if (v - start).abs() > (acc - start).abs() {
                        v
                    } else {
                        acc
                    }
                });
            return Some(Return {
                t_old: a.t + s * (b.t - a.t),
                increment_old: if s < 0.5 { a.increment } else { b.increment },
                reversed: cos < 0.0,
                t_turn,
            });
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector3};

    use super::*;

    fn state(u: f64, v: f64, t: f64) -> State {
        let mut s = State::at_rest(
            vec![Vector3::new(u, v, 0.0), Vector3::zeros()],
            vec![UnitQuaternion::identity(); 2],
        );
        s.t = t;
        s
    }

    #[test]
    fn a_retrace_and_a_loop_are_met_and_a_hairpin_is_not() {
        let reference = state(0.0, 0.0, 0.0);
        // Out along u, then back along the same line: found once two states confirm it.
        let mut m = PathMemory::new();
        m.restart(&reference, &reference, None);
        let mut found = None;
        for k in (1..=10).chain((0..10).rev()) {
            let u = f64::from(k);
            if let Some(r) = m.visit(&state(u, 0.0, u), &reference, None) {
                found = Some((u, r));
                break;
            }
        }
        let (u, r) = found.expect("the retrace is found");
        assert!(r.reversed && u >= 5.0 && (r.t_turn - 10.0).abs() < 1e-12, "u = {u}");
        // A circle closes a loop in the same sense.
        let mut m = PathMemory::new();
        m.restart(&reference, &reference, None);
        let found = (1..60).find_map(|k| {
            let a = f64::from(k) * 0.2;
            m.visit(&state(a.sin(), 1.0 - a.cos(), a), &reference, None)
        });
        assert!(found.is_some_and(|r| !r.reversed));
        // A hairpin (out along u, back along a parallel line a step away) is not the same path.
        let mut m = PathMemory::new();
        m.restart(&reference, &reference, None);
        let back: Vec<(f64, f64)> = (0..=10)
            .map(|k| (f64::from(k), 0.0))
            .chain((0..=10).rev().map(|k| (f64::from(k), 1.0)))
            .collect();
        assert!(back
            .iter()
            .all(|&(u, v)| m.visit(&state(u, v, u), &reference, None).is_none()));
    }

    #[test]
    fn a_branch_beside_the_old_one_with_another_stability_is_not_met() {
        let reference = state(0.0, 0.0, 0.0);
        // Out along u (stable), then back a tenth of a step beside it: met when the counts are
        // unknown or equal, not when the way back is unstable.
        let walk = |back: Option<usize>| {
            let mut m = PathMemory::new();
            m.restart(&reference, &reference, Some(0));
            (1..=10)
                .map(|k| (f64::from(k), 0.0, Some(0)))
                .chain((0..10).rev().map(|k| (f64::from(k), 0.1, back)))
                .find_map(|(u, v, n)| m.visit(&state(u, v, u), &reference, n))
        };
        assert!(walk(None).is_some_and(|r| r.reversed));
        assert!(walk(Some(0)).is_some_and(|r| r.reversed));
        assert!(walk(Some(1)).is_none());
    }
}

//! Events on arc-length paths: limit points of the load factor and extrema of a monitored
//! reaction are located between converged states, and stretches of the path along which the
//! monitored reaction changes much are refined, without changing the path itself. A zero of the
//! monitored reaction where the path is to stop ([`super::ZeroStop`]) is located the same way.
//!
//! Every extra equilibrium is found on a hyperplane across a chord between two converged states
//! `z_a`, `z_b` (`z = (q, lambda)`, in the arc-length metric): predictor `z_a + s (z_b - z_a)`
//! (for a zero, the nearest equilibrium found so far moved along the chord onto the plane),
//! corrections orthogonal to the chord (Riks' normal plane), so that `s` is a coordinate along the
//! path between them. An extremum is searched for in `s` by successive parabolic interpolation
//! with golden-section safeguards (Brent's minimisation without derivatives); the driver's state
//! (assembly, factorisation, mixed stresses) is saved before and restored after, so the path
//! resumes exactly as it would have.

use super::statics::{Driver, Increment};
use super::{Event, StaticPath, StaticStep, ZeroStop};
use crate::assembly::Assembled;
use crate::element::shell::ElementStress;
use crate::error::Result;
use crate::state::State;

/// A converged state of the path with what the location needs.
#[derive(Clone, Debug)]
pub(super) struct Point {
    pub state: State,
    /// Arc-length position on the path.
    pub arc: f64,
    /// The monitored reaction (0 without a monitor).
    pub monitor: f64,
}

/// Most evaluations spent on locating one event (a zero: twice as many, see `search_zero`).
const MAX_EVALUATIONS: usize = 12;
/// Most sub-segments a converged step is split into when refined.
const MAX_SPLIT: usize = 16;
/// Golden-section ratio.
const GOLDEN: f64 = 0.381_966_011_250_105_2;

/// What the driver was holding, restored after the location.
struct Saved {
    asm: Assembled,
    r: Vec<f64>,
    fresh: bool,
    factorised: bool,
    stress: (Vec<ElementStress>, bool),
}

/// An equilibrium found on a plane, with its position `s` along the chord.
pub(super) struct Found {
    pub s: f64,
    pub state: State,
    pub step: StaticStep,
    monitor: f64,
}

/// Changes of sign of the monitored reaction along a path, beyond its resolution.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ZeroWatch {
    /// The last value beyond the resolution of its state (0 before the first).
    last: f64,
}

impl ZeroWatch {
    /// Takes the monitored reaction `g` of the next state of the path and its resolution
    /// `floor` there (see [`Driver::zero_floor`]): whether its sign differs from that of the last
    /// value beyond its own floor. Values within the floor (the round-off of a reaction that
    /// starts at zero) carry no sign.
    pub fn crossed(&mut self, g: f64, floor: f64) -> bool {
        if g.is_nan() || g.abs() <= floor {
            return false;
        }
        let crossed = self.last != 0.0 && self.last.signum() != g.signum();
        self.last = g;
        crossed
    }
}

/// Motion of DOF `d` (0-2 translations, 3-5 rotations) of `node` from `a` to `b`: the
/// translation, or the spatial rotation vector `log(R_b R_a^T)`'s component.
fn dof_motion(a: &State, b: &State, node: usize, d: usize) -> f64 {
    if d < 3 {
        b.x[node][d] - a.x[node][d]
    } else {
        (b.q[node] * a.q[node].inverse()).scaled_axis()[d - 3]
    }
}

impl Driver<'_> {
    fn save(&mut self) -> Saved {
        Saved {
            asm: self.asm.clone(),
            r: self.r.clone(),
            fresh: self.fresh,
            factorised: self.factorised,
            stress: (self.stress.clone(), self.stress_valid),
        }
    }

    fn restore(&mut self, saved: Saved) -> Result<()> {
        self.asm = saved.asm;
        self.r = saved.r;
        (self.stress, self.stress_valid) = saved.stress;
        self.fresh = saved.fresh;
        self.factorised = false;
        if saved.factorised {
            // The same matrix factorised again: the same factors, bit for bit.
            self.factorise()?;
        }
        Ok(())
    }

    /// Increments `(dq, dlambda)` that take `a` to `b`: translations of the free DOFs, spatial
    /// rotation vectors `log(R_b R_a^T)` of the free rotations, and the load factor.
    pub(super) fn difference(&self, a: &State, b: &State) -> (Vec<f64>, f64) {
        let dq = self
            .system
            .dofs
            .free_dofs
            .iter()
            .map(|&(node, dof)| dof_motion(a, b, node, dof.index()))
            .collect();
        (dq, b.t - a.t)
    }

    /// The monitored reaction's resolution at the last assembled state \[N or N m\]: what Newton
    /// leaves of a residual (`tol_force` of the reference force, or the round-off floor), a moment
    /// taken times the characteristic length as the force norm weighs rotations.
    pub(super) fn zero_floor(&self) -> f64 {
        let floor = (self.conv.tol_force * self.reference_force()).max(self.conv.round_off);
        match self.params.monitor {
            Some(m) if m.dof.is_rotation() => floor * self.system.char_length,
            _ => floor,
        }
    }

    /// The equilibrium on the plane at fraction `s` of the chord from `from` (`None` if Newton
    /// fails there).
    pub(super) fn on_plane(
        &mut self,
        from: &State,
        chord: &(Vec<f64>, f64),
        s: f64,
        monitor: Option<usize>,
    ) -> Option<Found> {
        self.on_plane_from((from, 0.0), chord, s, monitor)
    }

    /// [`Self::on_plane`] from an equilibrium `from.0` on the plane at fraction `from.1` of the
    /// same chord: the predictor moves it along the chord by the difference, so that Newton starts
    /// beside the path, not on the chord, which a strongly curved path leaves far behind. (The
    /// plane reached is the one at `s` to first order in the rotations since `from.0`.)
    fn on_plane_from(
        &mut self,
        (from, origin): (&State, f64),
        chord: &(Vec<f64>, f64),
        s: f64,
        monitor: Option<usize>,
    ) -> Option<Found> {
        let mut state = from.clone();
        self.invalidate();
        let inc = Increment::Plane {
            chord: chord.0.clone(),
            chord_lambda: chord.1,
            fraction: s - origin,
        };
        let out = self.increment(&mut state, &inc).ok()?;
        let step = self.record(&state, &out).ok()?;
        let monitor = monitor.map_or(0.0, |i| step.reactions[i]);
        Some(Found {
            s,
            state,
            step,
            monitor,
        })
    }
}

/// Arc position of fraction `s` of the chord from `a` to `c`, through `b` at fraction `sb`.
fn arc_at(s: f64, (a, b, c): (f64, f64, f64), sb: f64) -> f64 {
    if s <= sb {
        a + (b - a) * s / sb.max(1e-300)
    } else {
        b + (c - b) * (s - sb) / (1.0 - sb).max(1e-300)
    }
}

/// After a converged step: locates the events between the last three converged states of
/// `history`, and refines the last step, inserting the states found into `path` (sorted by arc
/// position at the end of the path). `current` is the driver's state, unchanged on return.
pub(super) fn after_step(s: &mut Driver, history: &[Point], path: &mut StaticPath) -> Result<()> {
    let monitor = s.monitor_index();
    let n = history.len();
    if n >= 3 {
        let (a, b, c) = (&history[n - 3], &history[n - 2], &history[n - 1]);
        let mut kinds = Vec::new();
        if s.params.locate_limit_points {
            kinds.push((Event::LimitPoint, [a.state.t, b.state.t, c.state.t]));
        }
        if monitor.is_some() {
            kinds.push((Event::MonitorExtremum, [a.monitor, b.monitor, c.monitor]));
        }
        for (kind, g) in kinds {
            let sense = (g[1] - g[0]).signum();
            // An extremum of the monitor on a plateau (a change on either side below
            // `monitor_prominence` of its magnitude) is noise, not an event: not located. The
            // change before it is the whole monotonic run that leads to it, not the last step's:
            // a state just short of a sharp maximum would otherwise hide it.
            let prominent = match kind {
                Event::MonitorExtremum => {
                    let scale = g[1].abs() * s.params.monitor_prominence;
                    let rise = g[1] - run_start(&history[..n - 1], sense);
                    rise.abs() > scale && (g[1] - g[2]).abs() > scale
                }
                _ => true,
            };
            if prominent && (g[1] - g[0]) * (g[2] - g[1]) < 0.0 {
                locate(s, (a, b, c), kind, sense, path)?;
            }
        }
    }
    if n >= 2 && needs_refinement(s, &history[n - 2], &history[n - 1]) {
        let saved = s.save();
        let mut found = refine(s, &history[n - 2], &history[n - 1], monitor, 0);
        if s.params.switch_branches {
            // On a path that switches branches, a neutral mode (a fold free to slide) is not
            // counted, as at the path's own states.
            for f in &mut found {
                discount_neutral(s, f)?;
            }
        }
        s.restore(saved)?;
        s.stats.steps += found.len();
        path.steps.extend(found.into_iter().map(|f| f.step));
    }
    Ok(())
}

/// After a converged state whose monitored reaction changed sign (see [`ZeroWatch`]): the zero
/// where the path is to stop, located between the two states of `history` across which the sign
/// changed, if `stop_at_monitor_zero` asks for a zero of that kind. [`ZeroSearch::Absent`] if it
/// does not, or if those two states are not both in the history (the sign changed across a
/// jump); [`ZeroSearch::Missed`] if no zero is found between them (the reaction jumps across zero
/// there, or Newton fails). The driver's pieces are those of the zero on return if one is found
/// (the path ends there: they are not restored, which would factorise the last state's tangent
/// again), unchanged otherwise.
///
/// # Errors
/// A failure of the linear algebra when the driver's factorisation is restored.
pub(super) fn zero_to_stop_at(s: &mut Driver, history: &[Point]) -> Result<ZeroSearch> {
    let stop = s.params.stop_at_monitor_zero;
    let (Some(c), Some(m)) = (history.last(), s.params.monitor) else {
        return Ok(ZeroSearch::Absent);
    };
    // Back to the first state of the sign the reaction has now.
    let mut j = history.len() - 1;
    while j > 0 && history[j - 1].monitor * c.monitor > 0.0 {
        j -= 1;
    }
    if j == 0 {
        return Ok(ZeroSearch::Absent);
    }
    let (a, b) = (&history[j - 1], &history[j]);
    // The motion of the monitored DOF from `a` to `b`: beyond a resisting zero the reaction, the
    // force the constraint exerts, pushes along it. A DOF that does not move has none.
    let du = dof_motion(&a.state, &b.state, m.node, m.dof.index());
    if stop == ZeroStop::Never || (stop == ZeroStop::Resisting && b.monitor * du <= 0.0) {
        return Ok(ZeroSearch::Absent);
    }
    let saved = s.save();
    let monitor = s.monitor_index();
    if let Some(mut f) = search_zero(s, a, b, monitor) {
        f.step.arc = a.arc + f.s * (b.arc - a.arc);
        f.step.event = Some(Event::MonitorZero);
        if s.params.switch_branches {
            discount_neutral(s, &mut f)?;
        }
        return Ok(ZeroSearch::Found(Box::new(f)));
    }
    s.restore(saved)?;
    Ok(ZeroSearch::Missed {
        t: (a.state.t, b.state.t),
        monitor: (a.monitor, b.monitor),
    })
}

/// [`zero_to_stop_at`], the driver's pieces unchanged on return whatever it finds: for a
/// search before the state beyond the zero is recorded, which needs that state's.
///
/// # Errors
/// A failure of the linear algebra when the driver's factorisation is restored.
pub(super) fn zero_ahead(s: &mut Driver, history: &[Point]) -> Result<ZeroSearch> {
    let saved = s.save();
    let search = zero_to_stop_at(s, history)?;
    if let ZeroSearch::Found(_) = search {
        s.restore(saved)?;
    }
    Ok(search)
}

/// What [`zero_to_stop_at`] finds.
pub(super) enum ZeroSearch {
    /// No zero the path is to stop at between the two states.
    Absent,
    /// The zero, as a state of the path (its arc position and event set).
    Found(Box<Found>),
    /// The sign changed between the two states at load factors `t`, the reaction going from
    /// `monitor.0` to `monitor.1`, but no state between them brings it within its resolution of
    /// zero.
    Missed { t: (f64, f64), monitor: (f64, f64) },
}

impl ZeroSearch {
    /// Logs a missed zero: the path goes on past it.
    pub fn warn_if_missed(&self) {
        if let Self::Missed { t, monitor } = self {
            log::warn!(
                "the monitored reaction changed sign between load factors {} and {} ({:.3e} to \
                 {:.3e}) but no state there brings it within its resolution of zero (it jumps \
                 across zero, or Newton failed): the path goes on",
                t.0,
                t.1,
                monitor.0,
                monitor.1
            );
        }
    }
}

/// Searches the zero of the monitored reaction between `a` and `b`, where it has opposite signs,
/// by regula falsi along the chord (Illinois: the end that stays is halved in value so that the
/// bracket closes from both sides; bisection where Newton fails on the secant's plane), until the
/// reaction is within its resolution of zero ([`Driver::zero_floor`]: the state is then an
/// equilibrium without the constraint as closely as the path's states are with it). Each plane's
/// Newton starts from the bracket's nearer end, an equilibrium, moved onto it along the chord: on
/// the set-up's push near its folded equilibrium, Newton from the chord failed on planes between
/// two it had solved, 0.4 % of the chord apart. `None` if the
/// bracket closes to the load factor's round-off or `2 MAX_EVALUATIONS` planes are tried first (a
/// reaction that jumps across zero has none to find), or Newton fails on the secant's plane and
/// the bisection's. Where the reaction crosses zero more than once between `a` and `b` (steps
/// longer than the reaction's wiggles), the zero found may be any of them.
fn search_zero(s: &mut Driver, a: &Point, b: &Point, monitor: Option<usize>) -> Option<Found> {
    let chord = s.difference(&a.state, &b.state);
    let floor = s.zero_floor();
    // Bracket (s, reaction as regula falsi weighs it, load factor): `l` on `a`'s side of the zero.
    let mut l = (0.0, a.monitor, a.state.t);
    let mut r = (1.0, b.monitor, b.state.t);
    // The bracket's ends as equilibria, each plane's Newton starting from the nearer one.
    let mut ends = (a.state.clone(), b.state.clone());
    let tol = 1e-12 * a.state.t.abs().max(b.state.t.abs()).max(1.0);
    let mut kept = 0_i8;
    for _ in 0..2 * MAX_EVALUATIONS {
        let span = r.0 - l.0;
        // The secant's zero, kept off the ends.
        let secant = (l.0 - l.1 * span / (r.1 - l.1)).clamp(l.0 + 1e-3 * span, r.0 - 1e-3 * span);
        let mut solve = |at: f64| {
            let from = if at - l.0 <= r.0 - at {
                (&ends.0, l.0)
            } else {
                (&ends.1, r.0)
            };
            s.on_plane_from(from, &chord, at, monitor)
        };
        let f = solve(secant).or_else(|| solve(l.0 + 0.5 * span))?;
        let g = f.monitor;
        if g.abs() <= floor {
            return Some(f);
        }
        let point = (f.s, g, f.step.lambda);
        if g * a.monitor > 0.0 {
            l = point;
            ends.0 = f.state;
            if kept == 1 {
                r.1 *= 0.5;
            }
            kept = 1;
        } else {
            r = point;
            ends.1 = f.state;
            if kept == -1 {
                l.1 *= 0.5;
            }
            kept = -1;
        }
        if (r.2 - l.2).abs() < tol {
            return None;
        }
    }
    None
}

/// The monitored reaction where the monotonic run (in `sense`) ending at `points`' last point
/// began.
fn run_start(points: &[Point], sense: f64) -> f64 {
    let mut j = points.len() - 1;
    while j > 0 && (points[j].monitor - points[j - 1].monitor) * sense > 0.0 {
        j -= 1;
    }
    points[j].monitor
}

/// Before a jump from the limit point the path reached at `history`'s last state, the step to
/// `turned` having come back in load factor: locates the limit point between the state before,
/// the last one and `turned` (a point off the recorded path), inserting it into `path`; returns
/// its arc position, which the state jumped to must lie beyond. The driver's state is unchanged
/// on return.
pub(super) fn before_jump(
    s: &mut Driver,
    history: &[Point],
    turned: Point,
    path: &mut StaticPath,
) -> Result<Option<f64>> {
    let n = history.len();
    if n < 2 || !s.params.locate_limit_points {
        return Ok(None);
    }
    let (a, b) = (&history[n - 2], &history[n - 1]);
    let g = [a.state.t, b.state.t, turned.state.t];
    if (g[1] - g[0]) * (g[2] - g[1]) >= 0.0 {
        return Ok(None);
    }
    locate(s, (a, b, &turned), Event::LimitPoint, (g[1] - g[0]).signum(), path)
}

/// Locates the event `kind` between `a` and `c` (see [`search`]), the driver's state saved around
/// the search, and records it (see [`insert`]); returns its arc position if one was found.
fn locate(
    s: &mut Driver,
    (a, b, c): (&Point, &Point, &Point),
    kind: Event,
    sense: f64,
    path: &mut StaticPath,
) -> Result<Option<f64>> {
    let saved = s.save();
    let monitor = s.monitor_index();
    let found = search(s, (a, b, c), kind, sense, monitor);
    s.restore(saved)?;
    let arc = found.as_ref().map(|f| f.step.arc);
    insert(s, path, found, kind, b);
    Ok(arc)
}

/// Records the located event: the best state found. If the search found nothing better than the
/// converged state in the middle, that state is the best estimate; it stays a plain step of the
/// path (the path's states are never relabelled) and the event is not recorded.
fn insert(s: &mut Driver, path: &mut StaticPath, found: Option<Found>, kind: Event, middle: &Point) {
    if let Some(mut f) = found {
        f.step.event = Some(kind);
        s.stats.steps += 1;
        path.steps.push(f.step);
    } else {
        log::debug!("{kind:?} near t = {} not improved on by the search", middle.state.t);
    }
}

/// Searches the extremum of `sense * g` (g the load factor or the monitored reaction) between
/// `a` and `c`, where `b` is higher than both; returns the best new state if it beats `b`.
fn search(
    s: &mut Driver,
    (a, b, c): (&Point, &Point, &Point),
    kind: Event,
    sense: f64,
    monitor: Option<usize>,
) -> Option<Found> {
    let chord = s.difference(&a.state, &c.state);
    let c2 = s.arc_dot((&chord.0, chord.1), (&chord.0, chord.1));
    if c2.is_nan() || c2 <= 0.0 {
        return None;
    }
    let db = s.difference(&a.state, &b.state);
    let sb = (s.arc_dot((&db.0, db.1), (&chord.0, chord.1)) / c2).clamp(1e-3, 1.0 - 1e-3);
    let value = |t: f64, m: f64| {
        sense
            * match kind {
                Event::LimitPoint => t,
                _ => m,
            }
    };
    // Bracket (s, h, load factor); the middle one is the highest.
    let mut l = (0.0, value(a.state.t, a.monitor), a.state.t);
    let mut m = (sb, value(b.state.t, b.monitor), b.state.t);
    let mut r = (1.0, value(c.state.t, c.monitor), c.state.t);
    let tol = s.params.event_tolerance;
    let mut best: Option<Found> = None;
    for _ in 0..MAX_EVALUATIONS {
        // Parabola through the bracket: vertex, unless it falls outside or too near the middle.
        let (d1, d2) = (m.0 - l.0, m.0 - r.0);
        let (f1, f2) = (m.1 - l.1, m.1 - r.1);
        let den = d1 * f2 - d2 * f1;
        let vertex = m.0 - 0.5 * (d1 * d1 * f2 - d2 * d2 * f1) / den;
        let span = r.0 - l.0;
        let parabolic = den != 0.0 && vertex > l.0 && vertex < r.0 && (vertex - m.0).abs() > 1e-3 * span;
        let next = if parabolic {
            vertex
        } else if m.0 - l.0 > r.0 - m.0 {
            // Golden section into the larger side.
            m.0 - GOLDEN * (m.0 - l.0)
        } else {
            m.0 + GOLDEN * (r.0 - m.0)
        };
        let Some(f) = s.on_plane(&a.state, &chord, next, monitor) else {
            break;
        };
        let h = value(f.step.lambda, f.monitor);
        let point = (f.s, h, f.step.lambda);
        if h > m.1 {
            if point.0 < m.0 {
                r = m;
            } else {
                l = m;
            }
            m = point;
            best = Some(f);
        } else if point.0 < m.0 {
            l = point;
        } else {
            r = point;
        }
        let done = match kind {
            // The limit value is known once the points around the highest are within the
            // tolerance of it (a smooth maximum: they bound it from below, the parabola from above).
            Event::LimitPoint => m.1 - l.1.max(r.1) < tol,
            // The position of the extremum is known once the bracket is narrow in load factor.
            _ => (r.2 - l.2).abs() < tol,
        };
        if done {
            break;
        }
    }
    best.map(|mut f| {
        f.step.arc = arc_at(f.s, (a.arc, b.arc, c.arc), sb);
        f
    })
}

/// Whether the step from `b` to `c` is longer than `refine_span` in load factor while the
/// monitored reaction changes by more than `refine_change` of its magnitude.
fn needs_refinement(s: &Driver, b: &Point, c: &Point) -> bool {
    s.params
        .wants_refinement(c.state.t - b.state.t, b.monitor, c.monitor)
}

/// Recounts the negative eigenvalues of a state found with one, leaving out a neutral mode (see
/// [`Driver::negative_eigenvalues`]); the driver's pieces are then those of that state.
pub(super) fn discount_neutral(s: &mut Driver, f: &mut Found) -> Result<()> {
    if f.step.negative_eigenvalues == Some(1) {
        s.invalidate();
        s.assemble(&f.state);
        f.step.negative_eigenvalues = Some(s.negative_eigenvalues()?);
    }
    Ok(())
}

/// Parts a refined step from load factor `tb` to `tc` is split into.
fn refine_parts(s: &Driver, tb: f64, tc: f64) -> usize {
    // A margin over the span: the load factor is not exactly uniform along the chord.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let parts = ((1.05 * (tc - tb).abs() / s.params.refine_span).ceil() as usize).clamp(2, MAX_SPLIT);
    parts
}

/// What the refinement of the step from `b` to `c` finds on its first plane: nothing (`None`),
/// or an equilibrium, stable or not (`Some(stable)`; a negative eigenvalue at round-off level, a
/// neutral mode, does not count). The driver's pieces are unchanged on return.
///
/// # Errors
/// A failure of the linear algebra.
pub(super) fn first_plane(s: &mut Driver, b: &State, c: &State) -> Result<Option<bool>> {
    let saved = s.save();
    let chord = s.difference(b, c);
    #[allow(clippy::cast_precision_loss)]
    let first = 1.0 / refine_parts(s, b.t, c.t) as f64;
    let found = match s.on_plane(b, &chord, first, None) {
        None => Ok(None),
        Some(mut f) => discount_neutral(s, &mut f).map(|()| Some(f.step.negative_eigenvalues.is_none_or(|n| n == 0))),
    };
    s.restore(saved)?;
    found
}

/// Splits the step from `b` to `c` into equal parts along its chord if it needs refinement (see
/// [`needs_refinement`]), and refines the parts that still need it (up to 3 levels). Returns the
/// states found.
fn refine(s: &mut Driver, b: &Point, c: &Point, monitor: Option<usize>, depth: usize) -> Vec<Found> {
    if depth >= 3 || !needs_refinement(s, b, c) {
        return Vec::new();
    }
    let chord = s.difference(&b.state, &c.state);
    let parts = refine_parts(s, b.state.t, c.state.t);
    let mut found: Vec<Found> = Vec::new();
    for j in 1..parts {
        #[allow(clippy::cast_precision_loss)]
        let frac = j as f64 / parts as f64;
        let Some(mut f) = s.on_plane(&b.state, &chord, frac, monitor) else {
            break;
        };
        f.step.arc = b.arc + frac * (c.arc - b.arc);
        f.step.event = Some(Event::Refinement);
        found.push(f);
    }
    // Refine the parts that still change too much.
    let mut points: Vec<Point> = vec![b.clone()];
    points.extend(found.iter().map(|f| Point {
        state: f.state.clone(),
        arc: f.step.arc,
        monitor: f.monitor,
    }));
    points.push(c.clone());
    let mut more = Vec::new();
    for w in points.windows(2) {
        more.extend(refine(s, &w[0], &w[1], monitor, depth + 1));
    }
    found.extend(more);
    found
}

//! Analyses as sequences of steps: [`run`] carries one state (time, positions, rotations) through
//! the steps of a model, switching its constraints, loads and gravity at the start of each step as
//! the step says, and records one [`History`].
//!
//! Switching, in a static step:
//! * a constraint switched **on** holds its DOF where it is and moves it by
//!   `value * (f(t) - f(t_on))` from there;
//! * a constraint switched **off** is released without a jolt: its last reaction becomes a nodal
//!   load that decreases linearly to zero over the step (from the step's start to its final load
//!   factor), so the state stays in equilibrium at the start of the step;
//! * a load (or gravity) switched **off** decreases linearly to zero over the step in the same way;
//! * a load (or gravity) switched **on** acts as `value * f(t)` from the start of the step (give it
//!   a function that starts at zero there, such as a ramp, to apply it gradually).
//!
//! Dynamic and modal steps switch at once (a released constraint or load is simply gone). A modal
//! step ([`crate::solver::modal`]) computes the vibration modes of the current state without
//! changing it and adds no record: its [`crate::solver::Modes`] go to [`History::modes`].
//!
//! The numbering of the unknowns, the sparsity pattern and the symbolic factorisation are rebuilt
//! only when the set of constrained DOFs changes.

use std::time::Instant;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::assembly::{Assembled, System};
use crate::constraint::{Activity, DofMap, Slot};
use crate::dof::Dof;
use crate::error::{Clock, Error, Result};
use crate::model::{Load, Model};
use crate::options::Options;
use crate::output::{Fields, History, Outputs};
use crate::solver::{
    solve_dynamic, solve_modal, solve_static, Control, DynamicParams, EnergyBalance, ModalParams, StaticParams,
    StaticStep, Stats, ZeroStop,
};
use crate::state::State;
use crate::time_function::TimeFunction;

/// What a step computes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum StepKind {
    /// A static equilibrium path.
    Static(StaticParams),
    /// A transient dynamic analysis over a duration.
    Dynamic(DynamicParams),
    /// The vibration modes of the current state (which it does not change).
    Modal(ModalParams),
}

/// An analysis step: what it computes and what it switches at its start.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// Name (in messages and results).
    pub name: String,
    /// What the step computes.
    pub kind: StepKind,
    /// Ids of constraints, loads or gravity switched on at the start of the step.
    pub activate: Vec<String>,
    /// Ids switched off at the start of the step.
    pub deactivate: Vec<String>,
}

impl Step {
    /// A static step with `params`, switching nothing.
    #[must_use]
    pub fn new_static(name: &str, params: StaticParams) -> Self {
        Self {
            name: name.to_owned(),
            kind: StepKind::Static(params),
            activate: Vec::new(),
            deactivate: Vec::new(),
        }
    }

    /// A dynamic step with `params`, switching nothing.
    #[must_use]
    pub fn new_dynamic(name: &str, params: DynamicParams) -> Self {
        Self {
            name: name.to_owned(),
            kind: StepKind::Dynamic(params),
            activate: Vec::new(),
            deactivate: Vec::new(),
        }
    }

    /// A modal step with `params`, switching nothing.
    #[must_use]
    pub fn new_modal(name: &str, params: ModalParams) -> Self {
        Self {
            name: name.to_owned(),
            kind: StepKind::Modal(params),
            activate: Vec::new(),
            deactivate: Vec::new(),
        }
    }

    /// A step from a flat JSON object: `name`, `kind` (`"static"`, `"dynamic"` or `"modal"`),
    /// `activate` and `deactivate` (lists of ids), and the options of its kind (see
    /// [`StaticParams::from_options`], [`DynamicParams::from_options`] and
    /// [`ModalParams::from_options`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming a bad, inapplicable or unknown option.
    pub fn from_json(value: Value) -> Result<Self> {
        let mut o = Options::from_value(value, "step")?;
        let name: String = o.take_or("name", String::new())?;
        let kind: String = o.take_or("kind", "static".to_owned())?;
        let activate: Vec<String> = o.take_or("activate", Vec::new())?;
        let deactivate: Vec<String> = o.take_or("deactivate", Vec::new())?;
        let in_step = |e: Error| e.context(&format!("step '{name}'"));
        let kind = match kind.as_str() {
            "static" => StepKind::Static(StaticParams::from_options(o).map_err(in_step)?),
            "dynamic" => StepKind::Dynamic(DynamicParams::from_options(o).map_err(in_step)?),
            "modal" => StepKind::Modal(ModalParams::from_options(o).map_err(in_step)?),
            other => {
                return Err(Error::InvalidParameter(format!(
                    "step '{name}': unknown kind '{other}' (expected 'static', 'dynamic' or 'modal')"
                )))
            }
        };
        Ok(Self {
            name,
            kind,
            activate,
            deactivate,
        })
    }

    /// The step as the flat JSON object [`Step::from_json`] reads (every option explicit).
    #[must_use]
    pub fn to_json(&self) -> Value {
        let mut m: Map<String, Value> = Map::new();
        m.insert("name".into(), self.name.clone().into());
        let (kind, options) = match &self.kind {
            StepKind::Static(p) => ("static", p.to_options()),
            StepKind::Dynamic(p) => ("dynamic", p.to_options()),
            StepKind::Modal(p) => ("modal", p.to_options()),
        };
        m.insert("kind".into(), kind.into());
        m.insert("activate".into(), self.activate.clone().into());
        m.insert("deactivate".into(), self.deactivate.clone().into());
        m.extend(options);
        Value::Object(m)
    }

    fn static_params(&self) -> Option<&StaticParams> {
        match &self.kind {
            StepKind::Static(p) => Some(p),
            StepKind::Dynamic(_) | StepKind::Modal(_) => None,
        }
    }
}

/// Where a running analysis is, for progress reports.
#[derive(Clone, Copy, Debug)]
pub struct Progress<'a> {
    /// Index of the current step.
    pub step: usize,
    /// Its name.
    pub name: &'a str,
    /// Number of steps.
    pub n_steps: usize,
    /// Time (load factor) of the last converged state.
    pub t: f64,
    /// States recorded so far.
    pub records: usize,
}

/// The outcome of [`run`].
#[derive(Debug, Default)]
pub struct RunResult {
    /// Everything recorded, up to where the analysis stopped.
    pub history: History,
    /// Why the analysis stopped early, if it did (the history so far is kept).
    pub error: Option<Error>,
    /// True if the progress callback asked to stop.
    pub cancelled: bool,
    /// Counters and timings of each step that ran.
    pub step_stats: Vec<Stats>,
    /// Counters and timings of the whole analysis.
    pub stats: Stats,
    /// The last converged state.
    pub state: Option<State>,
    /// Steps completed.
    pub steps_completed: usize,
}

/// Checks a model, its steps and the outputs before anything runs.
fn validate(model: &Model, steps: &[Step], outputs: &Outputs) -> Result<()> {
    model.validate()?;
    if steps.is_empty() {
        return Err(Error::InvalidParameter("an analysis needs at least one step".into()));
    }
    let mut activity = Activity::initial(model);
    // The load factor (or time) each step starts from, where it is known before the run: a
    // displacement-controlled step ends wherever its path takes the load factor.
    let mut t = Some(0.0);
    for (k, step) in steps.iter().enumerate() {
        let name = &step.name;
        let context = format!("step {k} '{name}'");
        match &step.kind {
            StepKind::Static(p) => p.validate(),
            StepKind::Dynamic(p) => p.validate(),
            StepKind::Modal(p) => p.validate(),
        }
        .map_err(|e| e.context(&context))?;
        t = match &step.kind {
            StepKind::Static(p) => match p.control {
                Control::Load { lambda_end, .. } | Control::ArcLength { lambda_end, .. } => {
                    // A step that cannot move the load factor computed nothing and applied nothing
                    // it switched on (a constant load activated at the same load factor was
                    // silently left out).
                    if let Some(t0) = t {
                        if (lambda_end - t0).abs() <= 1e-12 * lambda_end.abs().max(1.0) {
                            return Err(Error::InvalidParameter(format!(
                                "{context}: lambda_end = {lambda_end} does not move the load factor \
                                 from the {t0} the step starts at (a static step applies what it \
                                 switches on along its range: give it one, e.g. lambda_end = {})",
                                t0 + 1.0
                            )));
                        }
                    }
                    // A path that stops at a zero of its monitored reaction ends where that lies.
                    (p.stop_at_monitor_zero == ZeroStop::Never).then_some(lambda_end)
                }
                Control::Displacement { .. } => None,
            },
            StepKind::Dynamic(p) => t.map(|t0| t0 + p.duration),
            StepKind::Modal(_) => t,
        };
        if let Some(id) = step.activate.iter().find(|id| step.deactivate.contains(id)) {
            // Deactivation is applied last: the activation would be silently void.
            return Err(Error::InvalidParameter(format!(
                "{context}: id '{id}' is both activated and deactivated"
            )));
        }
        for id in &step.activate {
            activity
                .switch(model, id, true)
                .map_err(|e| e.context(&context))?;
        }
        for id in &step.deactivate {
            activity
                .switch(model, id, false)
                .map_err(|e| e.context(&context))?;
        }
        let releases = !step.deactivate.is_empty() && k > 0;
        if releases
            && step
                .static_params()
                .is_some_and(|p| matches!(p.control, Control::Displacement { .. }))
        {
            return Err(Error::InvalidParameter(format!(
                "step {k} '{name}': constraints and loads are released over a step's load-factor range, \
                 which displacement control does not fix: release them in a load or arc-length step"
            )));
        }
        if releases
            && step
                .static_params()
                .is_some_and(|p| p.stop_at_monitor_zero != ZeroStop::Never)
        {
            // The released reactions would be left partly applied where the path stops.
            return Err(Error::InvalidParameter(format!(
                "step {k} '{name}': constraints and loads are released over a step's load-factor range, \
                 which a path that stops at a zero of its monitored reaction does not reach: release \
                 them in a step before it"
            )));
        }
    }
    outputs.reaction_dofs(model)?;
    Ok(())
}

/// The first dynamic step, where the model's initial velocities apply.
fn first_dynamic(steps: &[Step]) -> Option<usize> {
    steps
        .iter()
        .position(|s| matches!(s.kind, StepKind::Dynamic(_)))
}

/// Whether a static step comes before the first dynamic step: it holds the model at rest, so the
/// initial velocities are given when the dynamic step starts rather than to the initial state.
fn velocities_wait(steps: &[Step]) -> bool {
    first_dynamic(steps).is_some_and(|k| {
        steps[..k]
            .iter()
            .any(|s| matches!(s.kind, StepKind::Static(_)))
    })
}

/// Refuses an initial velocity component on a DOF that `dofs` constrains (its motion is the
/// constraint's, and the velocity's energy would be booked as numerical dissipation).
fn check_initial_velocities(model: &Model, dofs: &DofMap) -> Result<()> {
    for iv in &model.initial_velocities {
        let components = iv.velocity.iter().chain(iv.angular_velocity.iter());
        for (k, value) in components.enumerate() {
            if *value != 0.0 && matches!(dofs.slots[iv.node][k], Slot::Constrained(_)) {
                return Err(Error::InvalidModel(format!(
                    "node {} has an initial {} velocity of {value:e} on a constrained DOF: the \
                     constraint sets its motion (give initial velocities to free DOFs only)",
                    iv.node,
                    Dof::try_from_index(k)?.name()
                )));
            }
        }
    }
    Ok(())
}

/// Refuses, before any step runs, a dynamic or modal step in which a node has free DOFs without
/// mass or rotary inertia (a density of zero, a reference node carrying nothing), and an initial
/// velocity on a DOF that the first dynamic step constrains. Found when the step was reached,
/// the mass error came after the earlier steps' work, as a ValueError that dropped their results
/// (dynamic) or as a ConvergenceError (modal). Masses are checked in the reference orientation;
/// the dynamic step checks its own start again.
fn check_masses(model: &Model, system: &System, steps: &[Step]) -> Result<()> {
    let first = first_dynamic(steps);
    let mut activity = Activity::initial(model);
    for (k, step) in steps.iter().enumerate() {
        for id in &step.activate {
            activity.switch(model, id, true)?;
        }
        for id in &step.deactivate {
            activity.switch(model, id, false)?;
        }
        if matches!(step.kind, StepKind::Static(_)) {
            continue;
        }
        let dofs = DofMap::try_with(model, &activity)?;
        if first == Some(k) {
            check_initial_velocities(model, &dofs).map_err(|e| e.context(&format!("step {k} '{}'", step.name)))?;
        }
        for (i, slots) in dofs.slots.iter().enumerate() {
            if dofs.master[i].is_some() {
                continue;
            }
            let free: Vec<usize> = (0..6)
                .filter(|&d| matches!(slots[d], Slot::Free(_)))
                .collect();
            if free.is_empty() {
                continue;
            }
            let m = system.inertia[i].mass_matrix(&nalgebra::Matrix3::identity());
            let restricted = nalgebra::DMatrix::from_fn(free.len(), free.len(), |a, b| m[(free[a], free[b])]);
            if restricted.cholesky().is_none() {
                let names: Vec<&str> = free.iter().map(|&d| Dof::ALL[d].name()).collect();
                return Err(Error::InvalidModel(format!(
                    "step {k} '{}': node {i} has free DOFs {names:?} without mass or rotary inertia: a \
                     {} step needs mass on every free DOF (give its part a density, or attach a rigid \
                     body)",
                    step.name,
                    if matches!(step.kind, StepKind::Modal(_)) {
                        "modal"
                    } else {
                        "dynamic"
                    }
                )));
            }
        }
    }
    Ok(())
}

/// Gives the model's initial velocities to `state` (spatial, as the model's).
fn apply_initial_velocities(model: &Model, state: &mut State) {
    for iv in &model.initial_velocities {
        state.v[iv.node] = iv.velocity;
        state.w[iv.node] = iv.angular_velocity;
    }
}

/// The loads that release what step `step` switches off: the reactions of released constraints
/// (`reactions`, the static reactions at the current state, in `system`'s numbering of the
/// constraints active `before`) and the loads (and gravity) switched off, each decreasing
/// linearly to zero between the current time `t0` and the step's final load factor.
fn release_loads(
    model: &Model,
    system: &System,
    before: &Activity,
    after: &Activity,
    reactions: &[f64],
    t0: f64,
    t1: f64,
) -> Result<(Vec<Load>, Option<TimeFunction>)> {
    let to_zero = |at_t0: f64| TimeFunction::Table {
        points: if t1 > t0 {
            vec![(t0, at_t0), (t1, 0.0)]
        } else {
            vec![(t1, 0.0), (t0, at_t0)]
        },
    };
    let mut loads = Vec::new();
    for (k, c) in model.constraints.iter().enumerate() {
        if before.constraints[k] && !after.constraints[k] {
            let i = system
                .dofs
                .constraint_index
                .iter()
                .position(|&j| j == k)
                .expect("an active constraint is numbered");
            loads.push(Load {
                id: None,
                node: c.node,
                dof: c.dof,
                value: reactions[i],
                function: to_zero(1.0),
                active: true,
            });
        }
    }
    for (k, l) in model.loads.iter().enumerate() {
        if before.loads[k] && !after.loads[k] {
            loads.push(Load {
                function: to_zero(l.function.value(t0)),
                ..l.clone()
            });
        }
    }
    let gravity = model
        .gravity
        .as_ref()
        .filter(|_| before.gravity && !after.gravity)
        .map(|g| to_zero(g.function.value(t0)));
    if (!loads.is_empty() || gravity.is_some()) && t1 == t0 {
        return Err(Error::InvalidParameter(format!(
            "a static step that releases constraints or loads must move the load factor (it stays at {t0})"
        )));
    }
    Ok((loads, gravity))
}

/// The record of a state that was not reached by a solver (the initial state).
fn initial_record(system: &mut System, state: &State, stability: bool, fields: bool) -> Result<StaticStep> {
    let mut asm = Assembled::default();
    system.assemble(state, stability, &mut asm);
    let negative_eigenvalues = if stability {
        system.linear.factorize(&asm.k_ff)?;
        Some(system.linear.negative_eigenvalues()?)
    } else {
        None
    };
    let r = asm.residual();
    let n = |v: Vec<nalgebra::Vector3<f64>>| v.iter().map(|x| (*x).into()).collect();
    let zeros = if fields {
        vec![[0.0; 3]; state.x.len()]
    } else {
        Vec::new()
    };
    Ok(StaticStep {
        lambda: state.t,
        iterations: 0,
        residual: System::force_norm(&r, &system.free_weights()),
        energy: asm.energy,
        gravity_energy: asm.gravity_energy,
        reactions: asm.reactions(),
        negative_eigenvalues,
        displacements: zeros.clone(),
        rotations: zeros,
        markers: n(system.marker_positions(state)),
        marker_rotations: n(system.marker_rotations(state)),
        probes: system.probe(&asm),
        balance: Some(EnergyBalance {
            kinetic: system.kinetic_energy(state),
            ..EnergyBalance::default()
        }),
        ..StaticStep::default()
    })
}

/// Runs `steps` on `model` from its reference configuration, recording what `outputs` asks (and
/// the time, markers, energies and stability of every state). `progress` is called after each
/// converged state; returning `false` stops the analysis.
///
/// # Errors
/// An invalid model, step or output request is returned at once; a failure during the analysis is
/// reported in [`RunResult::error`] (naming the step and where it stopped) with everything
/// recorded so far.
pub fn run(
    model: &Model,
    steps: &[Step],
    outputs: &Outputs,
    progress: &mut dyn FnMut(&Progress) -> bool,
) -> Result<RunResult> {
    let start = Instant::now();
    validate(model, steps, outputs)?;
    let reaction_dofs = outputs.reaction_dofs(model)?;
    let interval = outputs.field_interval;
    let mut activity = Activity::initial(model);
    for id in &steps[0].activate {
        activity.switch(model, id, true)?;
    }
    for id in &steps[0].deactivate {
        activity.switch(model, id, false)?;
    }
    let mut system = System::try_with(model, &activity)?;
    check_masses(model, &system, steps)?;
    system.probes.clone_from(&reaction_dofs);
    let mut state = system.initial_state();
    let wait = velocities_wait(steps);
    if !wait {
        apply_initial_velocities(model, &mut state);
    }
    let mut result = RunResult::default();
    let history = &mut result.history;
    history.marker_names = model.markers.iter().map(|m| m.name.clone()).collect();
    history.reaction_dofs.clone_from(&reaction_dofs);
    let stability = steps[0].static_params().is_some_and(|p| p.stability);
    let first = initial_record(&mut system, &state, stability, interval > 0)?;
    history.push(0, first, interval > 0);
    let mut symbolic = 1;
    for (k, step) in steps.iter().enumerate() {
        if k > 0 {
            let before = activity.clone();
            for id in &step.activate {
                activity.switch(model, id, true)?;
            }
            for id in &step.deactivate {
                activity.switch(model, id, false)?;
            }
            // A static step releases over its load-factor range; a dynamic or modal one at once.
            let t1 = step.static_params().map(|p| match p.control {
                Control::Load { lambda_end, .. } | Control::ArcLength { lambda_end, .. } => lambda_end,
                Control::Displacement { .. } => state.t,
            });
            let (released, gravity_off) = match t1 {
                Some(t1) => {
                    // The released constraints' reactions at the state the step starts from, in
                    // the numbering of the constraints active until now: those recorded by the
                    // last static or dynamic step are numbered as they were then (a modal step
                    // may have switched constraints since) and, after a dynamic step, hold the
                    // inertia that a static step leaves out.
                    let reactions = if before
                        .constraints
                        .iter()
                        .zip(&activity.constraints)
                        .any(|(b, a)| *b && !*a)
                    {
                        let mut asm = Assembled::default();
                        system.assemble(&state, false, &mut asm);
                        asm.reactions()
                    } else {
                        Vec::new()
                    };
                    release_loads(model, &system, &before, &activity, &reactions, state.t, t1)
                        .map_err(|e| e.context(&format!("step {k} '{}'", step.name)))?
                }
                None => (Vec::new(), None),
            };
            let gravity = system.gravity.clone();
            if system
                .set_activity(model, &activity)
                .map_err(|e| e.context(&format!("step {k} '{}'", step.name)))?
            {
                symbolic += 1;
            }
            system.loads.extend(released);
            if let (Some(f), Some((g, _))) = (gravity_off, gravity) {
                system.gravity = Some((g, f));
            }
        }
        history.ndof.push(system.n_free());
        let context = format!("step {k} '{}'", step.name);
        if let StepKind::Modal(p) = &step.kind {
            match solve_modal(&mut system, &state, p) {
                Ok((mut modes, mut stats)) => {
                    log::info!(
                        "{context}: {} modes, lowest {:.6e} Hz, {} factorisations, {:.3} s",
                        modes.frequencies_hz.len(),
                        modes.frequencies_hz.first().copied().unwrap_or(f64::NAN),
                        stats.factorisations,
                        stats.wall_s
                    );
                    modes.step = k;
                    modes.name.clone_from(&step.name);
                    modes.record = history.len() - 1;
                    history.modes.push(modes);
                    stats.symbolic_analyses = std::mem::take(&mut symbolic);
                    result.stats.add(&stats);
                    result.step_stats.push(stats);
                }
                Err(e) => {
                    // Kept with the history so far, as a failed static or dynamic step is.
                    result.step_stats.push(Stats::default());
                    let clock = if steps[..k]
                        .iter()
                        .any(|s| matches!(s.kind, StepKind::Dynamic(_)))
                    {
                        Clock::Time
                    } else {
                        Clock::LoadFactor
                    };
                    result.error = Some(e.context(&context).on_clock(clock).in_step(&step.name));
                    break;
                }
            }
            if !progress(&Progress {
                step: k,
                name: &step.name,
                n_steps: steps.len(),
                t: state.t,
                records: history.len(),
            }) {
                result.cancelled = true;
                break;
            }
            result.steps_completed += 1;
            continue;
        }
        let n_steps = steps.len();
        let mut records = history.len();
        let mut cb = |s: &StaticStep, _: &Stats| {
            records += 1;
            progress(&Progress {
                step: k,
                name: &step.name,
                n_steps,
                t: s.lambda,
                records,
            })
        };
        let mut start_probes = None;
        let (records, mut stats, cancelled, error) = match &step.kind {
            StepKind::Static(p) => {
                let mut params = p.clone();
                params.record_fields = interval > 0;
                state.stop();
                let path = solve_static(&mut system, &mut state, &params, &mut cb).map_err(|e| e.context(&context))?;
                (path.steps, path.stats, path.cancelled, path.error)
            }
            StepKind::Dynamic(p) => {
                let mut params = p.clone();
                params.record_fields = interval > 0;
                if wait && first_dynamic(steps) == Some(k) {
                    apply_initial_velocities(model, &mut state);
                }
                let path = solve_dynamic(&mut system, &mut state, &params, &mut cb).map_err(|e| e.context(&context))?;
                start_probes = Some(path.start_probes);
                (path.steps, path.stats, path.cancelled, path.error)
            }
            StepKind::Modal(_) => unreachable!("modal steps are handled above"),
        };
        // The initial record of a run that starts moving (no step before this one recorded a
        // state: none, or modal ones): its reactions with the inertia of the consistent
        // accelerations (assembled statically they missed it: a pendulum released swinging
        // showed its weight where its pin felt the centripetal pull).
        if let (1, Some(p)) = (history.len(), start_probes) {
            let n = history.reaction_dofs.len();
            if p.len() == n && history.reactions.len() >= n {
                history.reactions[..n].copy_from_slice(&p);
            }
        }
        stats.symbolic_analyses = std::mem::take(&mut symbolic);
        log::info!(
            "{context}: {} increments ({} cut back), {} Newton iterations, {} factorisations, {} DOFs, \
             reached {} = {:.6e}, {:.3} s",
            stats.steps,
            stats.cutbacks,
            stats.iterations,
            stats.factorisations,
            system.n_free(),
            if matches!(step.kind, StepKind::Dynamic(_)) {
                "t"
            } else {
                "load factor"
            },
            state.t,
            stats.wall_s
        );
        result.stats.add(&stats);
        result.step_stats.push(stats);
        // Each step's last state too: the state the next step starts from (a release's) is
        // drawn and written whatever the interval.
        let n = records.len();
        for (j, s) in records.into_iter().enumerate() {
            let keep = interval > 0 && (history.len() % interval == 0 || j + 1 == n);
            history.push(k, s, keep);
        }
        if cancelled {
            result.cancelled = true;
            break;
        }
        if let Some(e) = error {
            result.error = Some(e.in_step(&step.name));
            break;
        }
        result.steps_completed += 1;
    }
    // The last state's fields, always.
    let last = history.len() - 1;
    if interval > 0 && history.fields.last().is_none_or(|f| f.record != last) {
        let (displacements, rotations) = system.fields(&state);
        history.fields.push(Fields {
            record: last,
            displacements,
            rotations,
        });
    }
    result.stats.wall_s = start.elapsed().as_secs_f64();
    result.state = Some(state);
    Ok(result)
}

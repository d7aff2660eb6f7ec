//! Runs a built model through settle and excitation, integrating wear per contact track
//! (thesis eq. 3.13-3.15, per track like the thesis' post-processor, summed per contact) and the
//! friction power `Σ N |v_slip|`, and collects what the reports need.

use crate::physics::body::BodyKind;
use crate::physics::control::RunControl;
use crate::physics::integrator::IntegratorSettings;
use crate::physics::partition::independent_parts;
use crate::physics::simulate::{
    simulate_from, DivergenceLimits, EngineCheckpoint, SimError, StepView,
};
use crate::physics::system::MultibodySystem;
use crate::physics::track::TrackSample;
use crate::wear::allocation::VolumeSplit;
use crate::wear::integrate::{TrackLoad, WearAccumulator};
use crate::wear::law::WearLaw;
use crate::wear::material::Material;
use crate::wear::mechanism::WearMechanism;
use crate::wear::WearError;
use serde::{Deserialize, Serialize};

mod parts;
mod rate_window;
mod records;
mod report;
mod samples;
mod soundness;
mod window_reports;

pub use rate_window::RateWindow;
pub use report::{BodyReport, ContactReport, RunReport};

use rate_window::Cumulative;
use records::{Appended, RecordMark, RecordWriter, VelocitySample};

use parts::run_parts;
use samples::{base_acceleration_at, record_tracks};
use window_reports::{window_reports, Totals, WindowReports};

/// A model ready to run: the system, its initial state and what each contact wears.
pub struct BuiltModel {
    /// Case name.
    pub name: String,
    /// The multibody system.
    pub system: MultibodySystem,
    /// Initial state (static guess: resting at the static penetration).
    pub initial_state: Vec<f64>,
    /// Time at which the excitation starts (end of settle), s.
    pub excitation_start_s: f64,
    /// Start of the rate window: the end of the excitation's ramp-in (settle + ramp), s; the
    /// run's rates are taken from here to the end ([`RateWindow`]).
    pub rate_start_s: f64,
    /// End of the run, s.
    pub end_time_s: f64,
    /// Material of body a and body b of each contact (same order as `system.contacts`).
    pub contact_materials: Vec<(Material, Material)>,
    /// Body whose acceleration is reported (spectra, VDV).
    pub response_body: usize,
}

impl BuiltModel {
    /// Start of the rate window of a model whose excitation starts at `excitation_start_s`
    /// and moves its base with `motion`: the end of the motion's ramp-in, not before the
    /// excitation starts.
    pub fn rate_start(excitation_start_s: f64, motion: &crate::excitation::BaseMotion) -> f64 {
        excitation_start_s.max(motion.settle_s() + motion.ramp_s())
    }
}

/// How a run is integrated, limited and post-processed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOptions {
    /// Integrator and tolerances.
    pub integrator: IntegratorSettings,
    /// Divergence bounds.
    pub limits: DivergenceLimits,
    /// Wear law.
    pub wear_law: WearLaw,
    /// Wear mechanism added to the law's wear on every track (`wear.mechanism`; None: the law
    /// alone), e.g. the one a gap diagnosis fitted.
    pub wear_mechanism: Option<WearMechanism>,
    /// Split of each contact's volume between its bodies.
    pub volume_split: VolumeSplit,
    /// Interval between recorded track samples, s (0: every accepted step; negative: none).
    pub record_interval_s: f64,
    /// Sample rate of the response acceleration record, Hz.
    pub response_rate_hz: f64,
}

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum ModelRunError {
    /// The simulation broke down or was cancelled.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// Wear post-processing rejected a value.
    #[error(transparent)]
    Wear(#[from] WearError),
    /// Stopped at an accepted step because a checkpoint was requested: resume with
    /// [`run_model_from`].
    #[error("checkpointed at t = {:.6} s", .0.time_s())]
    Checkpointed(Box<ModelCheckpoint>),
}

/// A model run stopped at an accepted step: everything [`run_model_from`] needs to finish it
/// with the result of the uninterrupted run, bit for bit. A model integrated part by part
/// keeps the reports of the parts already finished and the checkpoint of the one running.
/// What the run handed to its record sink before is not repeated here
/// (`records`): serialized, a checkpoint holds the records since the last
/// chunk, and one read back is whole again after [`ModelCheckpoint::restore_records`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ModelCheckpoint {
    /// Reports of the finished parts, in part order (empty for a model run whole).
    finished_parts: Appended<RunReport>,
    /// The run in progress: the engine's state and what the observer accumulated.
    current: WholeCheckpoint,
    /// The record chunks written before the checkpoint.
    records: RecordMark,
}

impl ModelCheckpoint {
    /// Simulated time of the run in progress, s.
    pub fn time_s(&self) -> f64 {
        self.current.engine.time_s
    }

    /// End of the run, s.
    pub fn end_time_s(&self) -> f64 {
        self.current.engine.end_time_s
    }

    /// Parts already finished (0 for a model run whole).
    pub fn finished_parts(&self) -> usize {
        self.finished_parts.len()
    }

    /// Record chunks the run handed to its record sink before the checkpoint.
    pub fn record_chunks(&self) -> u64 {
        self.records.chunks()
    }

    /// Puts the records together again from `chunks`, the record chunks of the run in order
    /// from the first (those after the ones the checkpoint counts are ignored); a checkpoint
    /// read back must be restored before it is resumed (also with no chunks, when it
    /// follows none). Refused, with the reason, when the chunks are not those the checkpoint
    /// follows.
    pub fn restore_records(&mut self, chunks: &[Vec<u8>]) -> Result<(), String> {
        records::restore(self, chunks)
    }

    /// True when no record is missing (restored, or never written out).
    fn complete(&self) -> bool {
        self.finished_parts.complete()
            && self.current.observed.tracks_out.complete()
            && self.current.observed.resp_vel.complete()
    }
}

/// One system's run at a checkpoint.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct WholeCheckpoint {
    engine: EngineCheckpoint,
    observed: Observed,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct TrackAcc {
    acc: WearAccumulator,
    open: bool,
}

/// What the observer of [`run_whole`] accumulates over the accepted steps: wear per track,
/// force and power integrals, recorded track samples, the response velocity on its grid and
/// the wear history, with the instants of their next samples.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Observed {
    accs: Vec<Vec<Option<TrackAcc>>>,
    normal_int: Vec<f64>,
    power_int: Vec<f64>,
    peak: Vec<f64>,
    prev_sums: Option<(f64, Vec<f64>, Vec<f64>)>,
    /// The energy account's friction work per contact at the window's first accepted state
    /// and at the last one, J.
    friction_at_window_start: Option<Vec<f64>>,
    friction_now: Vec<f64>,
    /// The cumulative quantities at the rate window's start, once the run has passed it.
    rate_base: Option<Cumulative>,
    tracks_out: Appended<TrackSample>,
    next_record: f64,
    next_resp: f64,
    resp_vel: Appended<VelocitySample>,
    prev_vel: Option<(f64, nalgebra::Vector3<f64>)>,
    wear_history: Vec<(f64, Vec<f64>)>,
    next_history: f64,
}

impl Observed {
    fn new(sys: &MultibodySystem, t0: f64) -> Self {
        let ncontacts = sys.contacts.len();
        Self {
            accs: sys
                .contacts
                .iter()
                .map(|c| {
                    (0..c.pieces_a.len() * c.faces_b.len())
                        .map(|_| None)
                        .collect()
                })
                .collect(),
            normal_int: vec![0.0; ncontacts],
            power_int: vec![0.0; ncontacts],
            peak: vec![0.0; ncontacts],
            prev_sums: None,
            friction_at_window_start: None,
            friction_now: vec![0.0; ncontacts],
            rate_base: None,
            tracks_out: Appended::default(),
            next_record: t0,
            next_resp: t0,
            resp_vel: Appended::default(),
            prev_vel: None,
            wear_history: Vec::new(),
            next_history: t0,
        }
    }

    /// The cumulative quantities now, stamped `t_s` (the last accepted step's time).
    fn cumulative(&self, t_s: f64) -> Cumulative {
        Cumulative {
            t_s,
            normal: self.normal_int.clone(),
            normal_slip: self.power_int.clone(),
            friction: self.friction_now.clone(),
            volume: self.volumes(),
        }
    }

    /// Wear volume per contact so far, m³.
    fn volumes(&self) -> Vec<f64> {
        self.accs
            .iter()
            .map(|l| l.iter().flatten().map(|a| a.acc.volume_m3()).sum())
            .collect()
    }

    /// True when the accumulators are shaped for `sys`'s contacts.
    fn fits(&self, sys: &MultibodySystem) -> bool {
        let n = sys.contacts.len();
        self.accs.len() == n
            && self
                .accs
                .iter()
                .zip(&sys.contacts)
                .all(|(a, c)| a.len() == c.pieces_a.len() * c.faces_b.len())
            && self.normal_int.len() == n
            && self.power_int.len() == n
            && self.friction_now.len() == n
            && self.peak.len() == n
    }
}

/// Runs the model and post-processes wear.
///
/// A model whose dynamic bodies fall into independent parts (several missiles on rails of one
/// prescribed launcher: [`crate::physics::partition`]) is run part by part, each with its own
/// integrator and step sizes, and the parts' reports are merged in the model's contact and
/// body order.
pub fn run_model(
    model: &BuiltModel,
    options: &RunOptions,
    control: &RunControl,
) -> Result<RunReport, ModelRunError> {
    run_model_from(model, options, control, None)
}

/// [`run_model`], or with `resume` its continuation from a checkpoint of the same model and
/// options ([`ModelRunError::Checkpointed`]): the report equals the uninterrupted run's bit for
/// bit (wall-clock time aside).
pub fn run_model_from(
    model: &BuiltModel,
    options: &RunOptions,
    control: &RunControl,
    resume: Option<ModelCheckpoint>,
) -> Result<RunReport, ModelRunError> {
    if let Some(cp) = resume.as_ref().filter(|cp| !cp.complete()) {
        return Err(bad_checkpoint(format!(
            "the checkpoint follows {} record chunks that were not restored",
            cp.record_chunks()
        )));
    }
    let parts = independent_parts(&model.system);
    let mark = resume
        .as_ref()
        .map(|cp| cp.records.clone())
        .unwrap_or_default();
    let mut writer = RecordWriter::new(control.record_sink.clone(), mark);
    if parts.len() > 1 {
        return run_parts(model, &parts, options, control, resume, &mut writer);
    }
    let result = match resume {
        Some(cp) if cp.finished_parts.len() > 0 => {
            return Err(bad_checkpoint(format!(
                "{} finished parts, the model runs whole",
                cp.finished_parts.len()
            )))
        }
        Some(cp) => run_whole(
            model,
            options,
            control,
            &mut |_| {},
            Some(cp.current),
            &mut writer,
        ),
        None => run_whole(model, options, control, &mut |_| {}, None, &mut writer),
    };
    result.map_err(|e| e.within_parts(Appended::default(), writer.mark()))
}

fn bad_checkpoint(reason: String) -> ModelRunError {
    ModelRunError::Sim(SimError::BadCheckpoint(reason))
}

/// Why [`run_whole`] stopped: a model run error, or a checkpoint of the one system.
enum WholeError {
    Run(ModelRunError),
    Checkpointed(Box<WholeCheckpoint>),
}

impl From<ModelRunError> for WholeError {
    fn from(e: ModelRunError) -> Self {
        WholeError::Run(e)
    }
}

impl From<SimError> for WholeError {
    fn from(e: SimError) -> Self {
        WholeError::Run(e.into())
    }
}

impl From<WearError> for WholeError {
    fn from(e: WearError) -> Self {
        WholeError::Run(e.into())
    }
}

impl WholeError {
    /// The model-level error; a checkpoint is kept with the reports of the parts finished
    /// before it and the mark of the record chunks written before it.
    fn within_parts(
        self,
        finished_parts: Appended<RunReport>,
        records: RecordMark,
    ) -> ModelRunError {
        match self {
            WholeError::Run(e) => e,
            WholeError::Checkpointed(current) => {
                ModelRunError::Checkpointed(Box::new(ModelCheckpoint {
                    finished_parts,
                    current: *current,
                    records,
                }))
            }
        }
    }
}

/// [`run_model`], also handing every accepted step of the excitation window (`t >=`
/// excitation start) to `extra` before the run's own post-processing sees it. The gap
/// diagnosis keeps each step's contact tracks this way, on the integrator's own time grid, so
/// that wear-law variants can be re-integrated exactly as the run integrates wear. The model is
/// integrated as one system (also when it has independent parts), so the steps come in time
/// order with the whole model's state.
///
/// `extra` keeps state of its own, so this run does not checkpoint: a checkpoint request
/// stops it as a cancellation.
pub fn run_model_observed(
    model: &BuiltModel,
    options: &RunOptions,
    control: &RunControl,
    extra: &mut dyn FnMut(&StepView),
) -> Result<RunReport, ModelRunError> {
    let mut writer = RecordWriter::new(None, RecordMark::default());
    run_whole(
        model,
        options,
        &control.without_checkpoint(),
        extra,
        None,
        &mut writer,
    )
    .map_err(|e| e.within_parts(Appended::default(), RecordMark::default()))
}

/// The states a run of `model` passes through, one per `every_s` of simulated time (the first
/// accepted step at or after each mark, from the first step on), each with its time, s: for
/// studies that evaluate contacts at recorded states. No track samples are kept.
pub fn record_states(
    model: &BuiltModel,
    options: &RunOptions,
    control: &RunControl,
    every_s: f64,
) -> Result<Vec<(f64, Vec<f64>)>, ModelRunError> {
    let mut options = *options;
    options.record_interval_s = -1.0;
    let mut states: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut next = f64::NEG_INFINITY;
    run_model_observed(model, &options, control, &mut |v| {
        if v.t >= next {
            states.push((v.t, v.state.to_vec()));
            next = v.t + every_s;
        }
    })?;
    Ok(states)
}

/// The run of a model integrated as one system (from `resume`, its checkpoint, if given),
/// writing its records to `writer` as they grow (`records`).
fn run_whole(
    model: &BuiltModel,
    options: &RunOptions,
    control: &RunControl,
    extra: &mut dyn FnMut(&StepView),
    resume: Option<WholeCheckpoint>,
    writer: &mut RecordWriter,
) -> Result<RunReport, WholeError> {
    let sys = &model.system;
    let t0 = model.excitation_start_s;
    let ncontacts = sys.contacts.len();
    let (mut st, engine) = match resume {
        Some(cp) => {
            if !cp.observed.fits(sys) {
                return Err(bad_checkpoint(
                    "the observer's accumulators do not fit the model's contacts".into(),
                )
                .into());
            }
            (cp.observed, Some(cp.engine))
        }
        None => (Observed::new(sys, t0), None),
    };
    let mut wear_error: Option<WearError> = None;
    // Response acceleration from velocity differences on a uniform grid.
    let dt_resp = 1.0 / options.response_rate_hz;
    let resp_offset = match sys.bodies[model.response_body].kind {
        BodyKind::Dynamic { offset } => Some(offset),
        BodyKind::Kinematic(_) => None,
    };
    let law = options.wear_law;
    // A track's accumulator: the law, plus the case's mechanism at the softer body's yield.
    let new_accumulator = |contact: usize| -> Result<WearAccumulator, WearError> {
        match options.wear_mechanism {
            None => WearAccumulator::new(law),
            Some(mechanism) => {
                let yield_pa = model
                    .contact_materials
                    .get(contact)
                    .map_or(f64::NAN, |(a, b)| {
                        a.yield_strength_pa.min(b.yield_strength_pa)
                    });
                WearAccumulator::with_mechanism(law, mechanism, yield_pa)
            }
        }
    };
    let history_dt = (model.end_time_s - t0) / 200.0;
    let mut watch = soundness::Watch::new(model);
    let mut observer = |v: &StepView| {
        watch.step(v);
        if v.t < t0 {
            return;
        }
        extra(v);
        // The step that passes the rate window's start: the cumulative quantities before it,
        // to be interpolated to the start once this step is added (`rate_window`).
        let rate_start = model.rate_start_s;
        let crossing = st.rate_base.is_none() && rate_start > t0 && v.t >= rate_start;
        let before = match &st.prev_sums {
            Some((tp, _, _)) if crossing => Some(st.cumulative(*tp)),
            _ => None,
        };
        // Friction work over the window: read off the energy account, so the report's friction
        // power is the account's.
        if st.friction_at_window_start.is_none() {
            st.friction_at_window_start = Some(v.friction_work_j.to_vec());
        }
        if v.friction_work_j.len() == st.friction_now.len() {
            st.friction_now.copy_from_slice(v.friction_work_j);
        }
        // Normal-load-times-slip power and normal force, trapezoid between step ends.
        let mut n_sum = vec![0.0; ncontacts];
        let mut p_sum = vec![0.0; ncontacts];
        for tr in v.tracks {
            let c = tr.contact as usize;
            n_sum[c] += tr.normal_force;
            p_sum[c] += tr.normal_force * tr.slip_speed;
            st.peak[c] = st.peak[c].max(tr.normal_force);
        }
        if let Some((tp, np, pp)) = &st.prev_sums {
            let dt = v.t - tp;
            for c in 0..ncontacts {
                st.normal_int[c] += 0.5 * dt * (np[c] + n_sum[c]);
                st.power_int[c] += 0.5 * dt * (pp[c] + p_sum[c]);
            }
        }
        st.prev_sums = Some((v.t, n_sum, p_sum));
        // Wear per track; a track that vanished is closed with a zero-force sample.
        for list in st.accs.iter_mut() {
            for a in list.iter_mut().flatten() {
                a.open = false;
            }
        }
        for tr in v.tracks {
            let slot = &mut st.accs[tr.contact as usize][tr.track as usize];
            let entry = match slot {
                Some(e) => e,
                None => match new_accumulator(tr.contact as usize) {
                    Ok(acc) => slot.insert(TrackAcc { acc, open: false }),
                    Err(e) => {
                        wear_error.get_or_insert(e);
                        continue;
                    }
                },
            };
            entry.open = true;
            let track = TrackLoad {
                normal_force_n: tr.normal_force,
                slip_speed_m_s: tr.slip_speed,
                area_m2: tr.area,
                damping_power_w: tr.damping_power.max(0.0),
                penetration_rate_m_s: tr.penetration_rate,
            };
            if let Err(e) = entry.acc.push_track(v.t, &track) {
                wear_error.get_or_insert(e);
            }
        }
        for list in st.accs.iter_mut() {
            for a in list.iter_mut().flatten() {
                if !a.open {
                    if let Err(e) = a.acc.push(v.t, 0.0, 0.0, 0.0) {
                        wear_error.get_or_insert(e);
                    }
                    a.open = true; // closed once; further zeros are harmless but skip them
                }
            }
        }
        if crossing {
            let after = st.cumulative(v.t);
            st.rate_base = Some(match before {
                Some(b) => b.interpolate_to(&after, rate_start),
                None => after,
            });
        }
        if v.t >= st.next_history {
            st.next_history = v.t + history_dt;
            let vols = st.volumes();
            st.wear_history.push((v.t, vols));
        }
        // Track samples for export.
        if options.record_interval_s >= 0.0 && v.t >= st.next_record {
            st.next_record = v.t + options.record_interval_s;
            record_tracks(v, st.tracks_out.items_mut());
        }
        // Response velocity, linearly interpolated onto the uniform grid.
        if let Some(off) = resp_offset {
            let vel = nalgebra::Vector3::new(v.state[off + 7], v.state[off + 8], v.state[off + 9]);
            if let Some((tp, vp)) = st.prev_vel {
                while st.next_resp <= v.t && v.t > tp {
                    let s = (st.next_resp - tp) / (v.t - tp);
                    let vi = vp + (vel - vp) * s.clamp(0.0, 1.0);
                    st.resp_vel.push((st.next_resp, [vi.x, vi.y, vi.z]));
                    st.next_resp += dt_resp;
                }
            }
            st.prev_vel = Some((v.t, vel));
        }
        writer.samples(&mut st.tracks_out, &mut st.resp_vel, false);
    };
    let mut y = model.initial_state.clone();
    let result = simulate_from(
        sys,
        &mut y,
        0.0,
        model.end_time_s,
        options.integrator,
        options.limits,
        control,
        &mut observer,
        engine,
    );
    if let Some(e) = wear_error {
        return Err(ModelRunError::from(e).into());
    }
    let stats = match result {
        Ok(stats) => stats,
        Err(SimError::Checkpointed(engine)) => {
            return Err(WholeError::Checkpointed(Box::new(WholeCheckpoint {
                engine: *engine,
                observed: st,
            })))
        }
        Err(e) => return Err(e.into()),
    };
    if writer.part_of_several {
        // The part's last samples, before its report follows them.
        writer.samples(&mut st.tracks_out, &mut st.resp_vel, true);
    }
    let Observed {
        mut accs,
        normal_int,
        power_int,
        peak,
        friction_at_window_start,
        friction_now,
        rate_base,
        tracks_out,
        resp_vel,
        wear_history,
        ..
    } = st;
    let friction_window: Vec<f64> = match &friction_at_window_start {
        Some(start) => rate_window::difference(&friction_now, start),
        None => vec![0.0; ncontacts],
    };
    // A broken run fails here rather than report zeros (`soundness`).
    let energy_controlled = options.integrator.tolerances.energy_rel > 0.0;
    watch.verdict(
        sys,
        stats.energy.as_ref(),
        energy_controlled,
        model.end_time_s,
    )?;
    if let Some(e) = stats.energy.as_ref().filter(|e| !e.balanced) {
        tracing::warn!(
            case = %model.name,
            residual_j = e.residual_j,
            residual_relative = e.residual_relative,
            "the energy account does not close within its bound (its work test was off): \
             results are suspect"
        );
    }
    let totals = Totals {
        accs: &mut accs,
        normal_int: &normal_int,
        normal_slip_int: &power_int,
        peak: &peak,
        friction_window: &friction_window,
        friction_now: &friction_now,
        rate_base,
    };
    let WindowReports {
        contacts,
        bodies,
        window_s: window,
        rate_window,
        mean_normal_force_n,
        mean_normal_slip_power_w,
        mean_friction_power_w,
    } = window_reports(model, options, totals)?;
    let resp_vel = resp_vel.into_items();
    let mut response_acceleration = Vec::with_capacity(resp_vel.len());
    let mut base_acceleration = Vec::with_capacity(resp_vel.len());
    for w in resp_vel.windows(2) {
        let dt = w[1].0 - w[0].0;
        response_acceleration.push([
            (w[1].1[0] - w[0].1[0]) / dt,
            (w[1].1[1] - w[0].1[1]) / dt,
            (w[1].1[2] - w[0].1[2]) / dt,
        ]);
        let tm = 0.5 * (w[0].0 + w[1].0);
        let a = base_acceleration_at(sys, tm);
        base_acceleration.push(a);
    }
    Ok(RunReport {
        mean_normal_force_n,
        mean_normal_slip_power_w,
        mean_friction_power_w,
        contacts,
        bodies,
        window_s: window,
        rate_window,
        integrator: stats.integrator,
        wall_s: stats.wall_s,
        tracks: tracks_out.into_items(),
        response_acceleration,
        response_rate_hz: options.response_rate_hz,
        base_acceleration,
        wear_history,
        energy: stats.energy,
        resumed_from_s: None,
    })
}

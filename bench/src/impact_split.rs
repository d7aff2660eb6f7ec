//! `impact-split`: where issue 28's error-control difference comes from. A case (rattle box C
//! by default) runs with full error control and with position-only error control without the
//! work test (the 5-7x faster mode of issue 16), and each run's time integral of `N·|v_slip|`
//! (the friction power users read), of friction power `μ N |v_slip|` and of damping power is
//! split, per contact track and accepted step, into the approach transient after each touch
//! and the rest. Three definitions of the approach transient are tabulated side by side:
//! - the steps that start within `--window-us` of the track's touch (the "first ~10 µs");
//! - the steps from the touch up to and including the first accepted state with `ẇ <= 0` (the
//!   approach until it is arrested, whatever it lasts);
//! - "fast normal motion": the touch's first step and every step with `|ẇ| > --fast-rate` at
//!   either end (an impact-like normal motion inside a persistent contact too: a cube slapping
//!   flat onto a wall it already touches with an edge stays one track).
//!
//! The first touches are restarted from before the touch, from the arrested state and from the
//! touch itself, resolved and through two hybrids (the frozen-rest impulse map, and the body
//! transient with all the body's contacts: `body_hybrid.rs`); `--hybrid-only` runs just what
//! the hybrids' comparison needs.
//!
//! A track touches at the first accepted step where it is active after a step where it was
//! not; the touch time is taken as that step's start (the integrator does not locate it).
//! Each step's trapezoid of a track's power goes whole to the part its classification names.

use super::body_hybrid::{
    body_hybrid_row, body_hybrid_start, body_hybrid_table, GroupResult,
    TIMED_REPEATS as BODY_REPEATS,
};
use super::supported_hybrid::{
    supported_hybrid_row, supported_hybrid_start, supported_hybrid_table,
};
use super::*;
use nalgebra::Point3;
use railwear::models::run::run_model_observed;
use railwear::physics::body::{effective_mass, frame_from_state, BodyKind};
use railwear::physics::body_transient::BodyTransientSettings;
use railwear::physics::friction::FrictionParams;
use railwear::physics::impact_map::{impact_map, ContactApproach, ImpactMapSettings};
use railwear::physics::integrator::ErrorControl;
use railwear::physics::system::MultibodySystem;
use std::collections::HashMap;

/// What `impact-split` runs.
pub(crate) struct ImpactSplitBench {
    pub(crate) cases: String,
    pub(crate) settle: f64,
    pub(crate) window: f64,
    /// Length of the approach window after a touch, s.
    pub(crate) approach_s: f64,
    /// |ẇ| above which a step is "fast normal motion", m/s.
    pub(crate) fast_rate_m_s: f64,
    /// Only what the hybrids need: the full run (for its touches), the resolved restarts from
    /// the touch and the two hybrids, with full control at the case tolerance and 64x it.
    pub(crate) hybrid_only: bool,
    /// The body transient's relative tolerance.
    pub(crate) transient_rtol: f64,
    /// The body transient's horizon, s.
    pub(crate) transient_horizon_s: f64,
    /// The supported map's supports without the frozen rotation's velocity offset.
    pub(crate) supports_translating: bool,
    /// The supported map's relative tolerance.
    pub(crate) supported_rtol: f64,
}

/// Power integrals, J: N·|v_slip| (N·m), friction, damping.
#[derive(Clone, Copy, Default)]
struct Works {
    normal_slip: f64,
    friction: f64,
    damping: f64,
}

impl Works {
    fn add(&mut self, dt: f64, a: &Powers, b: &Powers) {
        self.normal_slip += 0.5 * dt * (a.normal_slip + b.normal_slip);
        self.friction += 0.5 * dt * (a.friction + b.friction);
        self.damping += 0.5 * dt * (a.damping + b.damping);
    }
}

/// A track's powers and penetration rate at an accepted state.
#[derive(Clone, Copy, Default)]
struct Powers {
    normal: f64,
    normal_slip: f64,
    friction: f64,
    damping: f64,
    rate: f64,
}

/// A track between steps.
struct TrackMemory {
    touch_s: f64,
    arrested: bool,
    last: Option<Powers>,
    /// The touch's approach seen by the impulse map (None: a grazing touch, or not wanted),
    /// and the resolved damping work (J) and `∫N|v_slip| dt` (N·m) from the touch to the
    /// arrest so far.
    touch: Option<(ContactApproach, f64, f64)>,
    /// The touch's approach speed, m/s (from the state before it).
    approach_speed: Option<f64>,
    /// The state before the touch and the touch, kept until the arrested state is recorded too.
    before: Option<PendingRestart>,
}

/// One touch of the full run to restart from.
struct Restart {
    /// The accepted state before the touch.
    before: (f64, Vec<f64>),
    /// The first accepted state with the track active (the touch, `w` ~ 1e-7 m).
    touch: (f64, Vec<f64>),
    /// The touching track at `touch`, and the other tracks' `N·|v_slip|` there, W.
    track: railwear::physics::contact::TrackState,
    others_normal_slip: f64,
    /// The first accepted state at least [`ARRESTED_AFTER_S`] after the touch.
    arrested: (f64, Vec<f64>),
}

/// A [`Restart`] whose arrested state is not reached yet.
struct PendingRestart {
    before: (f64, Vec<f64>),
    touch: (f64, Vec<f64>),
    track: railwear::physics::contact::TrackState,
    others_normal_slip: f64,
}

/// A restarted run's start: time, state, end time.
type Start = (f64, Vec<f64>, f64);

/// Touches of the full run restarted from (the first ones of the window).
const RESTARTS: usize = 24;
/// Time after a touch by which its arrest is complete (the map: 1e-6..1e-5 s), s.
const ARRESTED_AFTER_S: f64 = 2e-5;
/// Tolerance factor of the loose full-control restarts (the ladder's loosest passing factor on
/// rattle box D; C passes at 100).
const LOOSE_FACTOR: f64 = 64.0;
/// Horizon of each restarted run, s (a wall episode of the full run lasts 12.6 ms at the median).
const RESTART_HORIZON_S: f64 = 0.02;

/// One touch of the full run against its impulse map.
struct TouchMap {
    approach: ContactApproach,
    resolved_damping_j: f64,
    map_damping_j: f64,
    /// The map with the body's translational mass as both effective masses (a flat face
    /// landing: its points lock the rotation), J.
    map_translational_damping_j: f64,
    map_normal_slip: f64,
    resolved_normal_slip: f64,
}

/// The approach of track `tr`'s touch as the impulse map sees it: the normal and tangential
/// effective masses of body a at the track's point (rotation included: `1 / (n·K n)` with
/// `K = I/m − [r]× I⁻¹ [r]×`, body b kinematic), and the point's approach speed and slip from
/// the state before the touch (`y_before` at `t_before`), ([`effective_mass`]). External force: none (15 g on the
/// 46 g cube over 10 µs is ~0.5 % of an impulse at 0.3 m/s).
fn touch_approach(
    system: &MultibodySystem,
    t_before: f64,
    y_before: &[f64],
    tr: &railwear::physics::contact::TrackState,
) -> Option<ContactApproach> {
    let c = &system.contacts[tr.contact as usize];
    let body = &system.bodies[c.body_a];
    let BodyKind::Dynamic { offset } = body.kind else {
        return None;
    };
    if !matches!(system.bodies[c.body_b].kind, BodyKind::Kinematic(_)) {
        return None;
    }
    let mut ws = system.workspace();
    system.frames(t_before, y_before, &mut ws);
    let a = frame_from_state(y_before, offset);
    let p: Point3<f64> = tr.point;
    let v_rel = a.point_velocity(&p) - ws.frames[c.body_b].point_velocity(&p);
    let n = tr.normal;
    let approach_speed = -n.dot(&v_rel);
    let slip = v_rel - n * n.dot(&v_rel);
    let r = p.coords - a.position;
    let tangent = if slip.norm() > 0.0 {
        slip.normalize()
    } else {
        n.cross(&Vector3::x())
            .try_normalize(1e-9)
            .unwrap_or_else(|| n.cross(&Vector3::y()))
    };
    let normal_mass = effective_mass(&body.mass, &a.rotation, &r, &n)?;
    let tangential_mass = effective_mass(&body.mass, &a.rotation, &r, &tangent)?;
    (approach_speed > 0.0).then(|| ContactApproach {
        normal_mass,
        tangential_mass,
        approach_speed,
        slip_velocity: [slip.norm(), 0.0],
        external_normal_force: 0.0,
        external_tangential_force: [0.0, 0.0],
    })
}

/// One run's split: [within window, rest], [until arrest, rest], [fast, rest].
#[derive(Default)]
struct Split {
    window: [Works; 2],
    arrest: [Works; 2],
    fast: [Works; 2],
    touches: u64,
    accepted: u64,
    cpu_s: Option<f64>,
    mean_normal_slip_power_w: f64,
    touch_maps: Vec<TouchMap>,
    /// Per separated episode: (duration from touch to the last active state, s, exit speed /
    /// approach speed).
    episodes: Vec<(f64, f64)>,
    /// Accepted steps in which some track is between its touch and its arrest, and in which
    /// some track's step starts within the approach window of its touch.
    approach_steps: u64,
    window_steps: u64,
    /// Accepted steps in which no track is before its arrest but some track is within 1 ms of
    /// its touch (the start of the creep on the slow manifold).
    creep_steps: u64,
    /// States to restart from, per touch (at most [`RESTARTS`]): the accepted state before the
    /// touch and the first accepted state at least [`ARRESTED_AFTER_S`] after it.
    restarts: Vec<Restart>,
    /// Per track (contact, track): ∫N·|v_slip| dt over the window, N·m.
    per_track: std::collections::BTreeMap<(u32, u32), (f64, f64)>,
}

fn run_split(
    configs_dir: &Path,
    case_name: &str,
    b: &ImpactSplitBench,
    mode: ErrorControl,
    work_test: bool,
    factor: f64,
    maps: Option<&ImpactMapSettings>,
) -> Result<Split> {
    let mut case = load_case(&configs_dir.join(format!("{case_name}.toml")))?;
    case.simulation.settle_s = b.settle;
    case.simulation.duration_s = b.window;
    case.simulation.rel_tolerance *= factor;
    case.simulation.abs_tolerance_m *= factor;
    case.simulation.error_control = mode;
    if !work_test {
        case.simulation.energy_rel_tolerance = Some(0.0);
    }
    let model = build(&case, configs_dir)?;
    let mut options = run_options(&case)?;
    options.record_interval_s = -1.0;
    let mut split = Split::default();
    let mut memory: HashMap<(u32, u32), TrackMemory> = HashMap::new();
    let mut seen_first = false;
    let mut y_before: Vec<f64> = Vec::new();
    let no_friction = FrictionParams {
        mu_static: 0.0,
        mu_dynamic: 0.0,
        ..FrictionParams::thesis_table_5_2()
    };
    let cpu0 = thread_cpu_s();
    let report = run_model_observed(&model, &options, &RunControl::silent(), &mut |v| {
        let now: HashMap<(u32, u32), Powers> = v
            .tracks
            .iter()
            .map(|tr| {
                (
                    (tr.contact, tr.track),
                    Powers {
                        normal: tr.normal_force,
                        normal_slip: tr.normal_force * tr.slip_speed,
                        friction: tr.friction_power,
                        damping: tr.damping_power,
                        rate: tr.penetration_rate,
                    },
                )
            })
            .collect();
        // The first step seen opens the window: nothing to integrate yet.
        let dt = if seen_first { v.t - v.t_prev } else { 0.0 };
        seen_first = true;
        for key in now.keys() {
            let m = memory.entry(*key).or_insert(TrackMemory {
                touch_s: v.t_prev,
                arrested: false,
                last: None,
                touch: None,
                approach_speed: None,
                before: None,
            });
            if m.last.is_none() {
                // A touch (or the track was active when the window opened).
                m.touch_s = v.t_prev;
                m.arrested = false;
                split.touches += 1;
                m.touch = None;
                m.approach_speed = None;
                if !y_before.is_empty() {
                    if let Some(tr) = v.tracks.iter().find(|tr| (tr.contact, tr.track) == *key) {
                        let approach = touch_approach(v.system, v.t_prev, &y_before, tr);
                        if maps.is_some() && split.restarts.len() < RESTARTS {
                            let others: f64 = v
                                .tracks
                                .iter()
                                .filter(|o| (o.contact, o.track) != *key)
                                .map(|o| o.normal_force * o.slip_speed)
                                .sum();
                            m.before = Some(PendingRestart {
                                before: (v.t_prev, y_before.clone()),
                                touch: (v.t, v.state.to_vec()),
                                track: *tr,
                                others_normal_slip: others,
                            });
                        }
                        m.approach_speed = approach.map(|a| a.approach_speed);
                        if maps.is_some() {
                            m.touch = approach.map(|a| (a, 0.0, 0.0));
                        }
                    }
                }
            }
        }
        let zero = Powers::default();
        let (mut in_approach_step, mut in_window_step, mut in_creep_step) = (false, false, false);
        for (key, m) in memory.iter_mut() {
            let after = now.get(key);
            let before = m.last.as_ref();
            if after.is_none() && before.is_none() {
                continue;
            }
            let a = before.unwrap_or(&zero);
            let e = after.unwrap_or(&zero);
            let first_step = before.is_none();
            if let (None, Some(last), Some(v_in)) = (after, before, m.approach_speed) {
                // A separation: the episode's duration and its exit speed over the approach
                // speed (the last active state's −ẇ).
                split
                    .episodes
                    .push((v.t_prev - m.touch_s, (-last.rate).max(0.0) / v_in));
            }
            let in_window = usize::from(v.t_prev >= m.touch_s + b.approach_s);
            let in_approach = usize::from(m.arrested);
            let fast =
                first_step || a.rate.abs() > b.fast_rate_m_s || e.rate.abs() > b.fast_rate_m_s;
            in_approach_step |= in_approach == 0;
            in_window_step |= in_window == 0;
            in_creep_step |= in_approach == 1 && v.t_prev < m.touch_s + 1e-3;
            let track = split.per_track.entry(*key).or_default();
            track.0 += 0.5 * dt * (a.normal_slip + e.normal_slip);
            track.1 += 0.5 * dt * (a.normal + e.normal);
            split.window[in_window].add(dt, a, e);
            split.arrest[in_approach].add(dt, a, e);
            split.fast[usize::from(!fast)].add(dt, a, e);
            if let Some((_, damping, normal_slip)) = m.touch.as_mut() {
                *damping += 0.5 * dt * (a.damping + e.damping);
                *normal_slip += 0.5 * dt * (a.normal_slip + e.normal_slip);
            }
            if e.rate <= 0.0 && !m.arrested {
                m.arrested = true;
                if let (Some((approach, damping, normal_slip)), Some(settings)) =
                    (m.touch.take(), maps)
                {
                    let c = &v.system.contacts[key.0 as usize];
                    let friction = c.friction.as_ref().unwrap_or(&no_friction);
                    let mass = v.system.bodies[c.body_a].mass.mass;
                    let translational = ContactApproach {
                        normal_mass: mass,
                        tangential_mass: mass,
                        ..approach
                    };
                    if let (Ok(map), Ok(map_translational)) = (
                        impact_map(&approach, &c.impact, friction, settings),
                        impact_map(&translational, &c.impact, friction, settings),
                    ) {
                        split.touch_maps.push(TouchMap {
                            map_translational_damping_j: map_translational.damping_dissipation,
                            approach,
                            resolved_damping_j: damping,
                            map_damping_j: map.damping_dissipation,
                            map_normal_slip: map.normal_force_slip_integral,
                            resolved_normal_slip: normal_slip,
                        });
                    }
                }
            }
            if after.is_some() && v.t >= m.touch_s + ARRESTED_AFTER_S {
                if let Some(pending) = m.before.take() {
                    if split.restarts.len() < RESTARTS {
                        split.restarts.push(Restart {
                            before: pending.before,
                            touch: pending.touch,
                            track: pending.track,
                            others_normal_slip: pending.others_normal_slip,
                            arrested: (v.t, v.state.to_vec()),
                        });
                    }
                }
            }
            if after.is_none() {
                m.before = None;
            }
            m.last = after.copied();
        }
        if dt > 0.0 {
            split.approach_steps += u64::from(in_approach_step);
            split.window_steps += u64::from(in_window_step);
            split.creep_steps += u64::from(in_creep_step && !in_approach_step);
        }
        y_before.clear();
        y_before.extend_from_slice(v.state);
    })
    .map_err(|e| anyhow!("{case_name} {}: {e}", mode.name()))?;
    split.cpu_s = thread_cpu_s().zip(cpu0).map(|(b, a)| b - a);
    split.accepted = report.integrator.accepted;
    split.mean_normal_slip_power_w = report.mean_normal_slip_power_w;
    Ok(split)
}

/// What the restarted runs of one mode measured, summed over the restarts.
#[derive(Default)]
struct Restarted {
    /// `∫N·|v_slip| dt` of all tracks over the first [`ARRESTED_AFTER_S`] of each run, N·m.
    early_normal_slip: f64,
    accepted: u64,
    touches: u64,
    separations: u64,
    normal_slip: f64,
    damping_j: f64,
    residual_j: f64,
    dissipated_j: f64,
}

/// Runs `model` from each start `(t0, y0)` to its `t_end` with the given error control, counting the tracks' touches and
/// separations and integrating `N·|v_slip|` and damping power (trapezoid over accepted steps).
fn restarted(
    model: &BuiltModel,
    options: &RunOptions,
    starts: &[Start],
    mode: ErrorControl,
    work_test: bool,
) -> Result<Restarted> {
    let mut settings = options.integrator;
    settings.tolerances.error_control = mode;
    if !work_test {
        settings.tolerances.energy_rel = 0.0;
    }
    let mut out = Restarted::default();
    for (t0, y0, t_end) in starts {
        let mut y = y0.clone();
        let mut last: HashMap<(u32, u32), (f64, f64)> = HashMap::new();
        let mut first = true;
        let stats = simulate(
            &model.system,
            &mut y,
            *t0,
            *t_end,
            settings,
            options.limits,
            &RunControl::silent(),
            &mut |v: &StepView| {
                let now: HashMap<(u32, u32), (f64, f64)> = v
                    .tracks
                    .iter()
                    .map(|tr| {
                        (
                            (tr.contact, tr.track),
                            (tr.normal_force * tr.slip_speed, tr.damping_power),
                        )
                    })
                    .collect();
                if !first {
                    let dt = v.t - v.t_prev;
                    let early = v.t <= t0 + ARRESTED_AFTER_S;
                    for (key, p) in &now {
                        let a = last.get(key).copied().unwrap_or((0.0, 0.0));
                        out.normal_slip += 0.5 * dt * (a.0 + p.0);
                        if early {
                            out.early_normal_slip += 0.5 * dt * (a.0 + p.0);
                        }
                        out.damping_j += 0.5 * dt * (a.1 + p.1);
                        out.touches += u64::from(!last.contains_key(key));
                    }
                    for (key, a) in &last {
                        if !now.contains_key(key) {
                            out.normal_slip += 0.5 * dt * a.0;
                            out.damping_j += 0.5 * dt * a.1;
                            out.separations += 1;
                        }
                    }
                }
                first = false;
                last = now;
            },
        )
        .map_err(|e| anyhow!("restart at {t0} s: {e}"))?;
        out.accepted += stats.integrator.accepted;
        if let Some(e) = stats.energy {
            out.residual_j += e.residual_j;
            out.dissipated_j += e.dissipated_j;
        }
    }
    Ok(out)
}

/// The hybrid's start for one touch: the impulse map of the touching track over
/// [`ARRESTED_AFTER_S`] with the body's translational mass (a flat landing) and the external
/// force frozen at the touch (gravity and the body's other tracks' forces, less the mass times
/// the kinematic body's acceleration, by central differences), its impulses applied to body a
/// as a velocity jump and its penetration written into a's position, at the end of the map;
/// the body's rotation frozen over the map. Returns the start and the map's `∫N|v_slip| dt` and
/// damping work plus the other tracks' `N·|v_slip|` frozen over the horizon (N·m, J). None when
/// the touch has no approach or the map fails.
fn hybrid_start(model: &BuiltModel, r: &Restart) -> Option<((f64, Vec<f64>), f64, f64)> {
    let system = &model.system;
    let (t, y) = &r.touch;
    let c = &system.contacts[r.track.contact as usize];
    let BodyKind::Dynamic { offset } = system.bodies[c.body_a].kind else {
        return None;
    };
    let mass = system.bodies[c.body_a].mass.mass;
    let n = r.track.normal;
    let p = r.track.point;
    let a = frame_from_state(y, offset);
    let mut ws = system.workspace();
    let mut wall_velocity = |time: f64| {
        system.frames(time, y, &mut ws);
        ws.frames[c.body_b].point_velocity(&p)
    };
    let dt = 1e-7;
    let wall_acceleration = (wall_velocity(t + dt) - wall_velocity(t - dt)) / (2.0 * dt);
    let v_rel = a.point_velocity(&p) - wall_velocity(*t);
    let approach_speed = -n.dot(&v_rel);
    let slip = v_rel - n * n.dot(&v_rel);
    let e1 = slip.try_normalize(0.0).unwrap_or_else(|| {
        n.cross(&Vector3::x())
            .try_normalize(1e-9)
            .unwrap_or_else(|| n.cross(&Vector3::y()).normalize())
    });
    let e2 = n.cross(&e1);
    // The body's force from everything but this track, frozen: gravity and the other tracks.
    let mut others = Vector3::zeros();
    system.tracks(*t, y, &mut ws, &mut |o| {
        if (o.contact, o.track) != (r.track.contact, r.track.track)
            && system.contacts[o.contact as usize].body_a == c.body_a
        {
            let s = o
                .slip_velocity
                .try_normalize(0.0)
                .unwrap_or_else(Vector3::zeros);
            others += o.normal * o.normal_force - s * o.friction_force;
        }
    });
    let body_force = system.gravity * mass + others;
    let relative_force = body_force - wall_acceleration * mass;
    let approach = ContactApproach {
        normal_mass: mass,
        tangential_mass: mass,
        approach_speed,
        slip_velocity: [slip.norm(), 0.0],
        external_normal_force: -n.dot(&relative_force),
        external_tangential_force: [e1.dot(&relative_force), e2.dot(&relative_force)],
    };
    let no_friction = FrictionParams {
        mu_static: 0.0,
        mu_dynamic: 0.0,
        ..FrictionParams::thesis_table_5_2()
    };
    let friction = c.friction.as_ref().unwrap_or(&no_friction);
    let settings = ImpactMapSettings {
        time_limit: ARRESTED_AFTER_S,
        ..ImpactMapSettings::default()
    };
    let map = impact_map(&approach, &c.impact, friction, &settings).ok()?;
    let tau = map.duration;
    let impulse =
        n * map.normal_impulse + e1 * map.tangential_impulse[0] + e2 * map.tangential_impulse[1];
    // The impulse's displacement along n: what the frozen relative motion would have
    // penetrated beyond the map's end penetration.
    let pushed_out = approach_speed * tau + 0.5 * approach.external_normal_force / mass * tau * tau
        - (map.end_penetration - r.track.penetration);
    let mut y_new = y.clone();
    for i in 0..3 {
        y_new[offset + i] +=
            a.velocity[i] * tau + 0.5 * body_force[i] / mass * tau * tau + n[i] * pushed_out;
        y_new[offset + 7 + i] += body_force[i] / mass * tau + impulse[i] / mass;
    }
    Some((
        (t + tau, y_new),
        map.normal_force_slip_integral + r.others_normal_slip * tau,
        map.damping_dissipation,
    ))
}

/// One definition of the approach transient: a run's [approach, rest] works.
type SplitPart = fn(&Split) -> &[Works; 2];
/// One integral of a [`Works`].
type WorkOf = fn(&Works) -> f64;

/// The `q` quantile (nearest rank) of `x`, None when empty.
fn quantile(mut x: Vec<f64>, q: f64) -> Option<f64> {
    if x.is_empty() {
        return None;
    }
    x.sort_by(f64::total_cmp);
    Some(x[((x.len() - 1) as f64 * q).round() as usize])
}

pub(crate) fn impact_split(configs_dir: &Path, b: &ImpactSplitBench) -> Result<Vec<Table>> {
    if !(b.window > 0.0 && b.approach_s > 0.0 && b.fast_rate_m_s > 0.0) {
        bail!("--window, --window-us and --fast-rate must be > 0");
    }
    let map_settings = ImpactMapSettings {
        time_limit: b.approach_s,
        ..ImpactMapSettings::default()
    };
    let variants = [
        ("full, tol", ErrorControl::Full, true, 1.0),
        (
            "positions, no work test, tol",
            ErrorControl::Positions,
            false,
            1.0,
        ),
        ("full, tol/4 (reference)", ErrorControl::Full, true, 0.25),
    ];
    let mut runs = Table::new(
        "Impact split: runs",
        &[
            ("case", "case"),
            ("variant", "variant"),
            ("accepted", "accepted"),
            ("cpu_s", "CPU s"),
            ("approach_steps", "steps touch → arrest"),
            ("window_steps", "steps within the window after touch"),
            ("creep_steps", "other steps within 1 ms after a touch"),
            ("touches_per_s", "touches per s"),
            ("mean_normal_slip_power_w", "mean N·\\|v_slip\\| W (report)"),
            ("episodes", "separations"),
            ("short", "separations within 10 ms of the touch"),
            ("duration", "median contact duration s"),
            ("restitution", "median exit / approach speed"),
            (
                "restitution_short",
                "median exit / approach speed, within 10 ms",
            ),
        ],
    );
    let mut parts = Table::new(
        "Impact split: time integrals over the window per part, and the fast mode's difference to full",
        &[
            ("case", "case"),
            ("split", "approach transient ="),
            ("quantity", "integral"),
            ("part", "part"),
            ("full", "full, tol"),
            ("positions", "positions, no work test"),
            ("reference", "full, tol/4"),
            ("diff", "positions − full"),
            ("share", "share of the total difference"),
        ],
    );
    let mut touches = Table::new(
        "Impact split: each touch of the full run against its impulse map (to the approach window)",
        &[
            ("case", "case"),
            ("touches", "touches mapped"),
            ("approach_speed", "median approach speed m/s"),
            ("normal_mass", "median m_n / body mass"),
            (
                "resolved_damping",
                "Σ resolved damping, touch to arrest (J)",
            ),
            ("map_damping", "Σ map damping (J)"),
            ("plastic", "Σ ½ m_n v_n² (J)"),
            ("damping_diff", "Σ map / Σ resolved − 1"),
            ("median_abs", "median \\|map/resolved − 1\\| per touch"),
            ("p90_abs", "90th percentile"),
            (
                "map_translational",
                "Σ map damping, m_n = m_t = body mass (J)",
            ),
            ("translational_diff", "Σ map (body mass) / Σ resolved − 1"),
            (
                "translational_median",
                "median \\|map (body mass)/resolved − 1\\| per touch",
            ),
            (
                "translational_max",
                "largest \\|map (body mass)/resolved − 1\\|",
            ),
            ("resolved_slip", "Σ resolved ∫N\\|v_slip\\| (N·m)"),
            ("map_slip", "Σ map ∫N\\|v_slip\\| (N·m)"),
        ],
    );
    let mut summary = body_hybrid_table();
    let mut supported_summary = supported_hybrid_table();
    let mut restart_table = Table::new(
        "Impact split: the full run's touches restarted, from before the touch and from the arrested state, in each mode",
        &[
            ("case", "case"),
            ("from", "restarted from"),
            ("mode", "mode"),
            ("restarts", "restarts"),
            ("accepted", "accepted steps"),
            ("touches", "touches"),
            ("separations", "separations"),
            ("normal_slip", "Σ ∫N·\\|v_slip\\| dt (N·m)"),
            ("normal_slip_diff", "vs full"),
            ("early", "of which in the first 20 µs (N·m)"),
            ("damping", "Σ damping work (J)"),
            ("residual", "Σ energy residual / Σ dissipated"),
        ],
    );
    let mut tracks = Table::new(
        "Impact split: ∫N·|v_slip| dt per contact track (N·m)",
        &[
            ("case", "case"),
            ("track", "contact/track (face)"),
            ("full", "full, tol"),
            ("positions", "positions, no work test"),
            ("reference", "full, tol/4"),
            ("share", "share of the total difference"),
            ("mean_n_full", "mean N full (N)"),
            ("mean_n_positions", "mean N positions (N)"),
            ("slip_full", "N-weighted mean slip full (m/s)"),
            ("slip_positions", "N-weighted mean slip positions (m/s)"),
        ],
    );
    for case_name in b.cases.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let mut measured = Vec::new();
        let variants = if b.hybrid_only {
            &variants[..1]
        } else {
            &variants[..]
        };
        for &(label, mode, work_test, factor) in variants {
            eprintln!("impact-split: {case_name} {label} ...");
            let maps = (measured.is_empty()).then_some(&map_settings);
            let s = run_split(configs_dir, case_name, b, mode, work_test, factor, maps)?;
            runs.row(vec![
                Cell::text(case_name),
                Cell::text(label),
                Cell::Int(s.accepted),
                Cell::opt(s.cpu_s),
                Cell::Int(s.approach_steps),
                Cell::Int(s.window_steps),
                Cell::Int(s.creep_steps),
                Cell::Num(s.touches as f64 / b.window),
                Cell::Num(s.mean_normal_slip_power_w),
                Cell::Int(s.episodes.len() as u64),
                Cell::Int(s.episodes.iter().filter(|e| e.0 < 0.01).count() as u64),
                Cell::opt(quantile(s.episodes.iter().map(|e| e.0).collect(), 0.5)),
                Cell::opt(quantile(s.episodes.iter().map(|e| e.1).collect(), 0.5)),
                Cell::opt(quantile(
                    s.episodes
                        .iter()
                        .filter(|e| e.0 < 0.01)
                        .map(|e| e.1)
                        .collect(),
                    0.5,
                )),
            ]);
            measured.push(s);
        }
        {
            let mut case = load_case(&configs_dir.join(format!("{case_name}.toml")))?;
            case.simulation.settle_s = b.settle;
            case.simulation.duration_s = b.window;
            let model = build(&case, configs_dir)?;
            let options = run_options(&case)?;
            // The tolerance ladder's loosest passing factor on C (docs/journal/benchmarks.md).
            let mut loose_case = case.clone();
            loose_case.simulation.rel_tolerance *= LOOSE_FACTOR;
            loose_case.simulation.abs_tolerance_m *= LOOSE_FACTOR;
            let loose = run_options(&loose_case)?;
            let restarts = &measured[0].restarts;
            let horizon = |t: f64| t + RESTART_HORIZON_S;
            let mut groups: Vec<(&str, Vec<Start>, f64, f64)> = vec![
                (
                    "before the touch",
                    restarts
                        .iter()
                        .map(|r| (r.before.0, r.before.1.clone(), horizon(r.before.0)))
                        .collect(),
                    0.0,
                    0.0,
                ),
                (
                    "arrested (touch + 20 µs)",
                    restarts
                        .iter()
                        .map(|r| (r.arrested.0, r.arrested.1.clone(), horizon(r.arrested.0)))
                        .collect(),
                    0.0,
                    0.0,
                ),
            ];
            if b.hybrid_only {
                groups.clear();
            }
            // The hybrids against the resolved run from the same touch state to the same end:
            // the frozen-rest map's and the body transient's, on the touches where both run.
            let mut supported = Vec::new();
            let (hybrid, bodies): (Vec<_>, Vec<_>) = restarts
                .iter()
                .filter_map(|r| {
                    let (t, y) = &r.touch;
                    let s = supported_hybrid_start(
                        &model,
                        *t,
                        y,
                        &r.track,
                        ARRESTED_AFTER_S,
                        b.supports_translating,
                        b.supported_rtol,
                    )?;
                    let map = hybrid_start(&model, r)?;
                    let (t, y) = &r.touch;
                    let settings = BodyTransientSettings {
                        horizon_s: b.transient_horizon_s,
                        relative_tolerance: b.transient_rtol,
                        ..BodyTransientSettings::default()
                    };
                    let body = body_hybrid_start(&model, *t, y, &r.track, &settings)?;
                    supported.push(s);
                    Some(((r, map), (&r.track, body)))
                })
                .unzip();
            groups.push((
                "the touch (first active state), resolved",
                hybrid
                    .iter()
                    .map(|(r, _)| (r.touch.0, r.touch.1.clone(), horizon(r.touch.0)))
                    .collect(),
                0.0,
                0.0,
            ));
            groups.push((
                "hybrid: map over 20 µs at the touch, then",
                hybrid
                    .iter()
                    .map(|(r, ((t, y), _, _))| (*t, y.clone(), horizon(r.touch.0)))
                    .collect(),
                hybrid.iter().map(|(_, h)| h.1).sum(),
                hybrid.iter().map(|(_, h)| h.2).sum(),
            ));
            groups.push((
                "hybrid: body transient over 20 µs at the touch, then",
                bodies
                    .iter()
                    .zip(&hybrid)
                    .map(|((_, h), (r, _))| (h.start.0, h.start.1.clone(), horizon(r.touch.0)))
                    .collect(),
                bodies.iter().map(|(_, h)| h.normal_slip()).sum(),
                bodies
                    .iter()
                    .map(|(_, h)| h.transient.damping_dissipation)
                    .sum(),
            ));
            groups.push((
                "hybrid: supported map over 20 µs at the touch, then",
                supported
                    .iter()
                    .zip(&hybrid)
                    .map(|(h, (r, _))| (h.start.0, h.start.1.clone(), horizon(r.touch.0)))
                    .collect(),
                supported.iter().map(|h| h.normal_slip).sum(),
                supported
                    .iter()
                    .map(|h| h.map.contact.damping_dissipation)
                    .sum(),
            ));
            let mut touch_full = None;
            let mut results: HashMap<(&str, &str), GroupResult> = HashMap::new();
            for (from, starts, map_slip, map_damping) in &groups {
                let mut full_slip = None;
                for (label, mode, work_test, opts) in [
                    ("full", ErrorControl::Full, true, &options),
                    ("full, tol × 64", ErrorControl::Full, true, &loose),
                    (
                        "positions, no work test",
                        ErrorControl::Positions,
                        false,
                        &options,
                    ),
                ] {
                    if b.hybrid_only && matches!(mode, ErrorControl::Positions) {
                        continue;
                    }
                    eprintln!("impact-split: {case_name} restarts {from}, {label} ...");
                    let cpu0 = thread_cpu_s();
                    let r = restarted(&model, opts, starts, mode, work_test)?;
                    let cpu_s = thread_cpu_s().zip(cpu0).map(|(b, a)| b - a);
                    let normal_slip = r.normal_slip + map_slip;
                    let base = if from.starts_with("hybrid") {
                        touch_full.unwrap_or(f64::NAN)
                    } else {
                        *full_slip.get_or_insert(normal_slip)
                    };
                    if from.starts_with("the touch") && touch_full.is_none() {
                        touch_full = Some(normal_slip);
                    }
                    restart_table.row(vec![
                        Cell::text(case_name),
                        Cell::text(*from),
                        Cell::text(label),
                        Cell::Int(starts.len() as u64),
                        Cell::Int(r.accepted),
                        Cell::Int(r.touches),
                        Cell::Int(r.separations),
                        Cell::Num(normal_slip),
                        Cell::text(format!("{:+.2} %", 100.0 * (normal_slip / base - 1.0))),
                        Cell::Num(r.early_normal_slip),
                        Cell::Num(r.damping_j + map_damping),
                        Cell::Num(r.residual_j.abs() / r.dissipated_j.max(1e-30)),
                    ]);
                    results.insert(
                        (*from, label),
                        GroupResult {
                            accepted: r.accepted,
                            normal_slip,
                            damping_j: r.damping_j + map_damping,
                            cpu_s,
                        },
                    );
                }
            }
            for mode in ["full", "full, tol × 64"] {
                let group = |from: &str| results.get(&(from, mode)).copied();
                let reference = results.get(&("the touch (first active state), resolved", "full"));
                if let (Some(reference), Some(resolved), Some(map), Some(body)) = (
                    reference.copied(),
                    group("the touch (first active state), resolved"),
                    group("hybrid: map over 20 µs at the touch, then"),
                    group("hybrid: body transient over 20 µs at the touch, then"),
                ) {
                    summary.row(body_hybrid_row(
                        case_name,
                        mode,
                        [reference, resolved, map, body],
                        &bodies,
                    ));
                    if let Some(s) = group("hybrid: supported map over 20 µs at the touch, then") {
                        let body_cpu: Option<f64> = bodies
                            .iter()
                            .map(|(_, h)| h.cpu_repeats_s.map(|s| s / BODY_REPEATS as f64))
                            .sum();
                        supported_summary.row(supported_hybrid_row(
                            case_name,
                            mode,
                            [reference, resolved, map, body, s],
                            body_cpu,
                            &supported,
                        ));
                    }
                }
            }
        }
        if b.hybrid_only {
            continue;
        }
        let total_of = |s: &Split| s.per_track.values().map(|t| t.0).sum::<f64>();
        let total_diff = total_of(&measured[1]) - total_of(&measured[0]);
        let keys: std::collections::BTreeSet<(u32, u32)> = measured
            .iter()
            .flat_map(|s| s.per_track.keys().copied())
            .collect();
        for key in keys {
            let at = |s: &Split| s.per_track.get(&key).map_or(0.0, |t| t.0);
            let mean_n = |s: &Split| s.per_track.get(&key).map_or(0.0, |t| t.1) / b.window;
            tracks.row(vec![
                Cell::text(case_name),
                Cell::text(format!("{}/{}", key.0, key.1)),
                Cell::Num(at(&measured[0])),
                Cell::Num(at(&measured[1])),
                Cell::Num(at(&measured[2])),
                Cell::text(format!(
                    "{:.1} %",
                    100.0 * (at(&measured[1]) - at(&measured[0])) / total_diff
                )),
                Cell::Num(mean_n(&measured[0])),
                Cell::Num(mean_n(&measured[1])),
                Cell::Num(at(&measured[0]) / b.window / mean_n(&measured[0])),
                Cell::Num(at(&measured[1]) / b.window / mean_n(&measured[1])),
            ]);
        }
        let maps = &measured[0].touch_maps;
        if !maps.is_empty() {
            let median = |mut x: Vec<f64>, q: f64| {
                x.sort_by(f64::total_cmp);
                x[((x.len() - 1) as f64 * q).round() as usize]
            };
            let body_mass = load_case(&configs_dir.join(format!("{case_name}.toml")))
                .ok()
                .and_then(|c| build(&c, configs_dir).ok())
                .and_then(|m| {
                    let c = m.system.contacts.first()?;
                    Some(m.system.bodies[c.body_a].mass.mass)
                })
                .unwrap_or(f64::NAN);
            let sum = |f: fn(&TouchMap) -> f64| maps.iter().map(f).sum::<f64>();
            let rel: Vec<f64> = maps
                .iter()
                .map(|t| (t.map_damping_j / t.resolved_damping_j - 1.0).abs())
                .collect();
            let rel_translational: Vec<f64> = maps
                .iter()
                .map(|t| (t.map_translational_damping_j / t.resolved_damping_j - 1.0).abs())
                .collect();
            touches.row(vec![
                Cell::text(case_name),
                Cell::Int(maps.len() as u64),
                Cell::Num(median(
                    maps.iter().map(|t| t.approach.approach_speed).collect(),
                    0.5,
                )),
                Cell::Num(median(
                    maps.iter()
                        .map(|t| t.approach.normal_mass / body_mass)
                        .collect(),
                    0.5,
                )),
                Cell::Num(sum(|t| t.resolved_damping_j)),
                Cell::Num(sum(|t| t.map_damping_j)),
                Cell::Num(sum(|t| {
                    0.5 * t.approach.normal_mass * t.approach.approach_speed.powi(2)
                })),
                Cell::text(format!(
                    "{:+.2} %",
                    100.0 * (sum(|t| t.map_damping_j) / sum(|t| t.resolved_damping_j) - 1.0)
                )),
                Cell::text(format!("{:.2} %", 100.0 * median(rel.clone(), 0.5))),
                Cell::text(format!("{:.2} %", 100.0 * median(rel, 0.9))),
                Cell::Num(sum(|t| t.map_translational_damping_j)),
                Cell::text(format!(
                    "{:+.3} %",
                    100.0
                        * (sum(|t| t.map_translational_damping_j) / sum(|t| t.resolved_damping_j)
                            - 1.0)
                )),
                Cell::text(format!(
                    "{:.3} %",
                    100.0 * median(rel_translational.clone(), 0.5)
                )),
                Cell::text(format!("{:.3} %", 100.0 * median(rel_translational, 1.0))),
                Cell::Num(sum(|t| t.resolved_normal_slip)),
                Cell::Num(sum(|t| t.map_normal_slip)),
            ]);
        }
        let splits: [(&str, SplitPart); 3] = [
            ("steps starting within the window after touch", |s| {
                &s.window
            }),
            ("touch until arrest (first ẇ <= 0)", |s| &s.arrest),
            ("touch step or |ẇ| > fast rate", |s| &s.fast),
        ];
        let quantities: [(&str, WorkOf); 3] = [
            ("∫N·|v_slip| dt (N·m)", |w| w.normal_slip),
            ("friction work ∫μN|v_slip| dt (J)", |w| w.friction),
            ("damping work (J)", |w| w.damping),
        ];
        for (split_name, get) in splits {
            for (q_name, q) in quantities {
                let total = |s: &Split| q(&get(s)[0]) + q(&get(s)[1]);
                let total_diff = total(&measured[1]) - total(&measured[0]);
                for (pi, part) in ["approach", "rest", "total"].into_iter().enumerate() {
                    let value = |s: &Split| match pi {
                        2 => total(s),
                        i => q(&get(s)[i]),
                    };
                    let diff = value(&measured[1]) - value(&measured[0]);
                    parts.row(vec![
                        Cell::text(case_name),
                        Cell::text(split_name),
                        Cell::text(q_name),
                        Cell::text(part),
                        Cell::Num(value(&measured[0])),
                        Cell::Num(value(&measured[1])),
                        Cell::Num(value(&measured[2])),
                        Cell::Num(diff),
                        Cell::text(format!("{:.1} %", 100.0 * diff / total_diff)),
                    ]);
                }
            }
        }
    }
    let setup = format!(
        "settle {} s, window {} s (integrals over the window); approach window {} µs after a \
         track's touch; fast rate {} m/s; tolerance factors on the case's rel and abs \
         tolerances; no track recording",
        b.settle,
        b.window,
        b.approach_s * 1e6,
        b.fast_rate_m_s
    );
    runs.note(setup.clone());
    runs.note(machine_note());
    parts.note(setup.clone());
    touches.note(setup);
    touches.note(
        "map: the touch's point as one contact with the contact's whole-face law, effective \
         masses of the cube at the track's point with rotation (m_n = 1/(n·K n)), approach \
         speed and slip of that point from the state before the touch, no external force, \
         horizon = the approach window; resolved: trapezoid of the track's damping power over \
         the accepted steps from the touch to the first state with ẇ <= 0",
    );
    restart_table.note(format!(
        "the first {RESTARTS} touches of the full run at the case tolerance; \"before the touch\" \
         and \"arrested\" run {h} s from the accepted state before the touch and from the first \
         accepted state {a} µs after it; \"the touch\" runs from the first accepted state with \
         the track active to {h} s after it, and the hybrid over the same span: the impulse map \
         over {a} µs at that state (the cube's translational mass, the external force frozen \
         there), its impulses applied as a velocity jump and its penetration written into the \
         pose, then the global integrator in the row's mode; the hybrid's integrals include the \
         map's and the other tracks' N·|v_slip| frozen over the map, and its Δ is against the \
         resolved full run from the touch; touches and separations count tracks appearing and \
         disappearing; integrals by the trapezoid over the accepted steps",
        h = RESTART_HORIZON_S,
        a = ARRESTED_AFTER_S * 1e6
    ));
    summary.note(
        "the restarted touches of the restart table; resolved = \"the touch (first active state), \
         resolved\", map hybrid = the frozen-rest impulse map over 20 µs (the cube's \
         translational mass), body hybrid = physics::body_transient over 20 µs (the cube's six \
         degrees of freedom with all its tracks, the tube on its prescribed motion, gravity; \
         Dormand-Prince 5(4), position tolerance 1e-12 m, a step across a change of the loaded \
         points at 1e-3 of the tolerance); ∫N|v_slip| dt and damping work summed over the \
         touches, each hybrid's including its transient's; \"vs resolved\" against the \
         resolved run in the row's mode, \"vs case tol\" against the resolved run at the case \
         tolerance; CPU from /proc/thread-self/stat (10 ms ticks)",
    );
    summary.note(format!(
        "body transient relative tolerance {:e}, horizon {} µs (the rows' labels say 20 µs)",
        b.transient_rtol,
        b.transient_horizon_s * 1e6
    ));
    summary.note(machine_note());
    supported_summary.note(
        "the restarted touches of the restart table; supported hybrid = \
         physics::supported_impact_map over 20 µs at the touch (the cube's translational mass, \
         the touching track's law; the cube's other pressed tracks with a normal off the wall's \
         as rigid supports, tracks on one normal merged, their friction on their own slip with \
         the frozen rotation's offset; gravity, the tube's inertia and unpressed tracks frozen), its velocity change and displacement applied to the cube, \
         the rotation frozen, then the global integrator in the row's mode; integrals summed \
         over the touches, each hybrid's including its map's or transient's; CPU from \
         /proc/thread-self/stat (10 ms ticks; a map's CPU over 200 repeats)",
    );
    supported_summary.note(if b.supports_translating {
        "supports translating (--supports-translating): no velocity offset, each support point \
         moves with the touching point"
    } else {
        "supports with the frozen rotation's velocity offset (the support point's velocity \
         relative to the touching point at the touch, N-weighted over the merged tracks)"
    });
    supported_summary.note(format!(
        "supported map relative tolerance {:e}",
        b.supported_rtol
    ));
    supported_summary.note(machine_note());
    Ok(vec![
        runs,
        parts,
        touches,
        tracks,
        restart_table,
        summary,
        supported_summary,
    ])
}

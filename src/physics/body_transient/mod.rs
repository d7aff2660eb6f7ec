//! The contact-local transient of one free rigid body with all its contacts (issue 28: the
//! "several contacts of one body" that the 1-D impulse map leaves out).
//!
//! [`crate::physics::impact_map`] carries one contact's normal transient with the rest of the system
//! frozen. On the rattle boxes that misses 1.5-2.3 % of `∫N|v_slip| dt`: while the wall arrests
//! the cube, the floor's load rises, and a frozen floor cannot show it (docs/reference/models.md, "Where
//! position-only error control's difference comes from"). Here the whole body moves instead:
//! its six degrees of freedom (position, unit quaternion, world velocity, body-frame angular
//! velocity, as in [`crate::physics::system`]) under gravity, its force elements and every contact it
//! has, each evaluated by the engine's own per-point law ([`crate::physics::contact`]: IMPACT with the
//! STEP ramp and the clamp, the regularized Coulomb friction with its stick/slip regimes), while
//! the kinematic bodies it touches follow their prescribed motion over the horizon. Nothing is
//! linearised and no effective mass is chosen: a flat landing locks the rotation by itself.
//!
//! The integrator is the array Dormand–Prince 5(4) of [`crate::physics::local_dopri5`] with Hairer's PI
//! step control, on a fixed-size state (the body, the time, and the quadratures the caller
//! needs: damping, friction and element dissipation, gravity, drive and applied work, and per
//! touched track `∫N dt`, the friction impulse, `∫N|v_t| dt`, its damping and friction work),
//! so a transient allocates only at its start (the list of the body's contacts and elements,
//! the frames of the other bodies) and once for its result. Unlike the 1-D map it does not land
//! on the law's switches: each contact point has its own (touch, ramp end, clamp), hundreds per
//! body, and the error control resolves them by rejected steps instead; the energy account
//! (tests/engine/body_transient.rs) shows what that costs in accuracy. The step is explicit, so
//! it is limited by the damping's time scale `m/c_max` (~1e-7 s on the rattle boxes' cube)
//! for as long as a contact is pressed: this is for horizons of the order of an arrest
//! (1e-5 s), not for the persistent contact after it.

use crate::field_error::FieldError;
use crate::physics::body::{BodyKind, BODY_STATE_LEN};
use crate::physics::contact::{GeometryCache, GeometryMode};
use crate::physics::impact_map::{positive, relative_tolerance};
use crate::physics::local_dopri5::{dopri5_step, PiControl};
use crate::physics::system::MultibodySystem;
use nalgebra::Vector3;

mod rhs;

use rhs::{
    normalize_quaternion, Evaluator, State, TrackNow, DIM, E_DAMP, E_ELEM, E_FRIC, OMEGA,
    PER_TRACK, POS, QUAT, TIME, TRACKS, T_DAMP, T_FRIC, T_NSLIP, T_PN, T_PT, VEL, W_APPLIED,
    W_DRIVE, W_GRAV,
};

/// Most distinct tracks (contact, piece × face) a transient can book: each has its
/// quadratures in the fixed-size state. The rattle box's cube has six (four walls, two caps).
pub const MAX_TRACKS: usize = 16;

/// Error control and horizon of a transient.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyTransientSettings {
    /// Relative tolerance per step on the velocities and the quadratures (each against its own
    /// scale: the larger of the body's speed at the start and 1 mm/s, the momentum and kinetic
    /// energy at that speed). Default 1e-8.
    pub relative_tolerance: f64,
    /// Absolute tolerance per step on the position (and on the quaternion, as this length at
    /// the body's radius of gyration), m. Default 1e-12 m: 1e-7 of the rattle boxes' static
    /// penetration (21 µm), so the contact forces are as accurate as the velocities.
    pub position_tolerance_m: f64,
    /// Length of the transient, s. Default 2e-5 s: the rattle boxes' arrests end within
    /// 1e-6..1e-5 s (docs/reference/models.md).
    pub horizon_s: f64,
    /// Most step attempts (accepted and rejected) before [`TransientEnd::StepLimit`].
    /// Default 1e5.
    pub max_steps: usize,
    /// Tolerance of a step across which the number of loaded contact points changes (a touch,
    /// a separation, the clamp: kinks of the force law that the steps do not land on), as a
    /// fraction of the tolerances above. The embedded estimate sees a kink at a lower order
    /// than it has, and underestimates its error: an undamped impact closes its energy to
    /// ~1e-6 with 1 here and the default tolerances, to ~1e-9 with 1e-3 (tests/engine/
    /// body_transient.rs). Default 1e-3.
    pub switch_tolerance_factor: f64,
}

impl Default for BodyTransientSettings {
    fn default() -> Self {
        Self {
            relative_tolerance: 1e-8,
            position_tolerance_m: 1e-12,
            horizon_s: 2e-5,
            max_steps: 100_000,
            switch_tolerance_factor: 1e-3,
        }
    }
}

impl BodyTransientSettings {
    /// Checks every field: tolerances finite in (0, 1) and > 0, horizon finite > 0, steps >= 1.
    pub fn validate(&self) -> Result<(), FieldError> {
        relative_tolerance("relative_tolerance", self.relative_tolerance)?;
        positive("position_tolerance_m", self.position_tolerance_m)?;
        positive("horizon_s", self.horizon_s)?;
        if self.max_steps == 0 {
            return Err(FieldError::new("max_steps", "must be at least 1"));
        }
        let f = self.switch_tolerance_factor;
        if !(f.is_finite() && f > 0.0 && f <= 1.0) {
            return Err(FieldError::new(
                "switch_tolerance_factor",
                format!("must be a finite number in (0, 1], got {f}"),
            ));
        }
        Ok(())
    }
}

/// How the transient ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransientEnd {
    /// The horizon was reached.
    Horizon,
    /// [`BodyTransientSettings::max_steps`] attempts were spent first.
    StepLimit,
}

/// What one track (a piece of one contact against one face) took part in over the transient.
/// Forces and impulses are those on the transient's body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransientTrack {
    /// Index of the contact in the system.
    pub contact: u32,
    /// Track index within the contact (as [`crate::physics::contact::TrackState::track`]).
    pub track: u32,
    /// `∫N dt`, N·s: the normal impulse, and the wear law's time integral of the load.
    pub normal_impulse: f64,
    /// Friction impulse on the body, `∫(F − N n) dt`, N·s, world.
    pub tangential_impulse: Vector3<f64>,
    /// `∫N |v_t| dt` (the points' `Σ N_i |v_i|`), N·m: Archard's load times slip distance.
    pub normal_force_slip_integral: f64,
    /// Energy the track's damping and clamp dissipated, J (>= 0).
    pub damping_dissipation: f64,
    /// Energy the track's friction dissipated, J (>= 0).
    pub friction_dissipation: f64,
    /// Time (from the start) of the first accepted state with the track active, s (NaN when
    /// it was active only inside steps, at stages).
    pub first_active_s: f64,
    /// Time of the first accepted state after an approach (`ẇ > 0`) with `ẇ <= 0`: the
    /// track's arrest, s (None: not arrested within the horizon, or never approaching).
    pub arrest_s: Option<f64>,
    /// The track's contact normal (out of the face's body) at its last active evaluation,
    /// world: the direction of its normal impulse on body a.
    pub normal: Vector3<f64>,
    /// Active (some point touching) at the end.
    pub active_at_end: bool,
    /// Penetration of the deepest point at the end, m (0 when inactive).
    pub end_penetration: f64,
    /// Its rate at the end, m/s (positive approaching).
    pub end_penetration_rate: f64,
}

/// What a transient hands back: the body's end state, the energies, every track's integrals.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyTransient {
    /// How it ended.
    pub end: TransientEnd,
    /// Time integrated, s (the horizon unless [`TransientEnd::StepLimit`]).
    pub duration: f64,
    /// The body's end state in the system's layout ([`BODY_STATE_LEN`] entries: position,
    /// unit quaternion w i j k, world velocity, body-frame angular velocity).
    pub end_state: [f64; BODY_STATE_LEN],
    /// Kinetic energy at the start and at the end, J.
    pub kinetic_energy: [f64; 2],
    /// Energy stored in the body's contacts and force elements at the start and at the end, J.
    pub stored_energy: [f64; 2],
    /// Energy dissipated by contact damping (and the clamp), J.
    pub damping_dissipation: f64,
    /// Energy dissipated by friction, J.
    pub friction_dissipation: f64,
    /// Energy dissipated by the body's force elements, J.
    pub element_dissipation: f64,
    /// Work of gravity on the body, J.
    pub gravity_work: f64,
    /// Work the kinematic bodies' prescribed motion did through the contacts and elements
    /// (minus the work of the forces on them), J.
    pub drive_work: f64,
    /// Work of applied loads (constant forces), J.
    pub applied_work: f64,
    /// Every track active at some accepted state or stage, in order of first activity.
    pub tracks: Vec<TransientTrack>,
    /// Accepted steps.
    pub steps: usize,
    /// Rejected step attempts.
    pub rejected_steps: usize,
}

impl BodyTransient {
    /// Dissipated energy, J.
    pub fn dissipated(&self) -> f64 {
        self.damping_dissipation + self.friction_dissipation + self.element_dissipation
    }

    /// Work done on the body from outside (gravity, drive, applied loads), J.
    pub fn external_work(&self) -> f64 {
        self.gravity_work + self.drive_work + self.applied_work
    }

    /// The energy account's residual `E_end + W_diss − W_ext − E_start`, J (E kinetic plus
    /// stored; gravity is external work, not a potential).
    pub fn energy_residual(&self) -> f64 {
        self.kinetic_energy[1] + self.stored_energy[1] + self.dissipated()
            - self.external_work()
            - self.kinetic_energy[0]
            - self.stored_energy[0]
    }

    /// Writes the end state into the system state `y` at the body's `offset`.
    pub fn write_end_state(&self, y: &mut [f64], offset: usize) {
        y[offset..offset + BODY_STATE_LEN].copy_from_slice(&self.end_state);
    }
}

/// Why a transient could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BodyTransientError {
    /// A field of the [`BodyTransientSettings`] breaks its rule.
    #[error("body transient settings: {0}")]
    Settings(FieldError),
    /// The start (body index, time, state) breaks its rule.
    #[error("body transient start: {0}")]
    Start(FieldError),
    /// A contact or force element couples the body to another dynamic body: the transient
    /// moves one body against prescribed ones.
    #[error("body transient: `{element}` couples the body to the dynamic body `{other}`")]
    CoupledToDynamicBody {
        /// The contact's or force element's name.
        element: String,
        /// The other dynamic body's name.
        other: String,
    },
    /// More than [`MAX_TRACKS`] distinct tracks became active.
    #[error("body transient: more than {MAX_TRACKS} tracks active at t = {time} s")]
    TooManyTracks {
        /// Time since the start, s.
        time: f64,
    },
    /// The step size fell below the resolution of the time (a non-finite state).
    #[error("body transient step size underflow at t = {time} s")]
    StepSizeUnderflow {
        /// Time since the start, s.
        time: f64,
    },
}

impl BodyTransientError {
    /// The offending field's name, for input errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            Self::Settings(e) | Self::Start(e) => Some(&e.field),
            _ => None,
        }
    }
}

/// Integrates dynamic body `body` of `system` from the system state `y` at time `t` over
/// `settings.horizon_s`, with all its contacts and force elements, the kinematic bodies on
/// their prescribed motion. `y` is not changed: the end state is in the result
/// ([`BodyTransient::write_end_state`]).
pub fn body_transient(
    system: &MultibodySystem,
    body: usize,
    t: f64,
    y: &[f64],
    settings: &BodyTransientSettings,
) -> Result<BodyTransient, BodyTransientError> {
    settings.validate().map_err(BodyTransientError::Settings)?;
    let start = |field: &str, rule: String| BodyTransientError::Start(FieldError::new(field, rule));
    let Some(b) = system.bodies.get(body) else {
        return Err(start(
            "body",
            format!(
                "must index a body of the system ({} bodies), got {body}",
                system.bodies.len()
            ),
        ));
    };
    let BodyKind::Dynamic { offset } = b.kind else {
        return Err(start(
            "body",
            format!("must be a dynamic body, `{}` is kinematic", b.name),
        ));
    };
    if !t.is_finite() {
        return Err(start("t", format!("must be finite, got {t}")));
    }
    if y.len() != system.state_len() {
        return Err(start(
            "y",
            format!(
                "must have the system's {} entries, got {}",
                system.state_len(),
                y.len()
            ),
        ));
    }
    let own = &y[offset..offset + BODY_STATE_LEN];
    if own.iter().any(|x| !x.is_finite()) {
        return Err(start(
            "y",
            format!("the body `{}`'s state must be finite", b.name),
        ));
    }
    let mass = b.mass.mass;
    let inverse_inertia = b
        .mass
        .inertia
        .try_inverse()
        .filter(|_| mass > 0.0)
        .ok_or_else(|| {
            start(
                "body",
                format!(
                    "`{}` must have a positive mass and an invertible inertia",
                    b.name
                ),
            )
        })?;

    // The body's contacts and elements; the other side must be prescribed.
    let mut kinematic = Vec::new();
    let mut reach = |other: usize, element: &str| -> Result<(), BodyTransientError> {
        match system.bodies[other].kind {
            BodyKind::Kinematic(_) => {
                if !kinematic.contains(&other) {
                    kinematic.push(other);
                }
                Ok(())
            }
            BodyKind::Dynamic { .. } if other == body => Ok(()),
            BodyKind::Dynamic { .. } => Err(BodyTransientError::CoupledToDynamicBody {
                element: element.to_string(),
                other: system.bodies[other].name.clone(),
            }),
        }
    };
    let mut contacts = Vec::new();
    for (i, c) in system.contacts.iter().enumerate() {
        let sign = if c.body_a == body {
            1.0
        } else if c.body_b == body {
            -1.0
        } else {
            continue;
        };
        reach(c.body_a, &c.name)?;
        reach(c.body_b, &c.name)?;
        contacts.push((i, sign));
    }
    let mut elements = Vec::new();
    for (i, e) in system.forces.iter().enumerate() {
        let ends = e.bodies();
        if !ends.contains(&Some(body)) {
            continue;
        }
        for other in ends.into_iter().flatten() {
            reach(other, e.name())?;
        }
        elements.push(i);
    }
    let mut ws = system.workspace();
    system.frames(t, y, &mut ws);
    let mut ev = Evaluator {
        system,
        body,
        mass,
        inertia: b.mass.inertia,
        inverse_inertia,
        contacts,
        elements,
        kinematic,
        frames: ws.frames,
        wrenches: vec![(Vector3::zeros(), Vector3::zeros()); system.bodies.len()],
        geometry: GeometryCache::default(),
        slots: [(0, 0); MAX_TRACKS],
        slot_count: 0,
        overflow: false,
        now: [TrackNow::default(); MAX_TRACKS],
        last_normal: [Vector3::zeros(); MAX_TRACKS],
        stored: 0.0,
        loaded_points: 0,
    };

    let mut state: State = [0.0; DIM];
    state[..BODY_STATE_LEN].copy_from_slice(own);
    normalize_quaternion(&mut state);
    state[TIME] = t;
    // The overlaps' volumes and areas are recorded at the start and held (`Frozen`): each
    // point's penetration, and so every force, is still computed exactly from the poses, and
    // the transient reads no area; the full overlap is ~85 % of an evaluation's cost.
    ev.geometry.set_mode(GeometryMode::Record);
    let mut f0 = ev.derivative(&state);
    ev.geometry.set_mode(GeometryMode::Frozen);
    let mut loaded_at_state = ev.loaded_points;
    let kinetic_start = ev.kinetic_energy(&state);
    let stored_start = ev.stored;

    // Error scales: positions absolute; velocities, impulses and energies relative to the
    // body's speed at the start (at least 1 mm/s), its momentum and kinetic energy.
    let gyration = (b.mass.inertia.trace() / (2.0 * mass)).sqrt();
    let speed = Vector3::new(own[VEL], own[VEL + 1], own[VEL + 2])
        .norm()
        .max(Vector3::new(own[OMEGA], own[OMEGA + 1], own[OMEGA + 2]).norm() * gyration)
        .max(1e-3);
    let rtol = settings.relative_tolerance;
    let mut absolute = [rtol * 0.5 * mass * speed * speed; DIM];
    absolute[POS..POS + 3].fill(settings.position_tolerance_m);
    absolute[QUAT..QUAT + 4].fill(settings.position_tolerance_m / gyration);
    absolute[VEL..VEL + 3].fill(rtol * speed);
    absolute[OMEGA..OMEGA + 3].fill(rtol * speed / gyration);
    absolute[TIME] = f64::INFINITY;
    for s in 0..MAX_TRACKS {
        let base = TRACKS + s * PER_TRACK;
        absolute[base + T_PN..base + T_NSLIP].fill(rtol * mass * speed);
        absolute[base + T_NSLIP] = rtol * mass * speed * speed;
    }
    // Relative part only where the component's size sets its accuracy (not the positions,
    // whose size is where the body is).
    let relative: [f64; DIM] = std::array::from_fn(|i| {
        if (POS..QUAT).contains(&i) || i == TIME {
            0.0
        } else {
            rtol
        }
    });

    let max_damping = ev
        .contacts
        .iter()
        .map(|&(c, _)| system.contacts[c].impact.max_damping)
        .fold(0.0f64, f64::max);
    let mut h = 1e-3 * settings.horizon_s;
    if max_damping > 0.0 {
        h = h.min(0.1 * mass / max_damping);
    }
    let t_end = t + settings.horizon_s;
    let (mut steps, mut rejected) = (0usize, 0usize);
    let mut control = PiControl::default();
    let mut end = TransientEnd::Horizon;
    let mut first_active = [f64::NAN; MAX_TRACKS];
    let mut approaching = [false; MAX_TRACKS];
    let mut arrest = [None; MAX_TRACKS];
    let mut record = |ev: &Evaluator<'_>, time: f64| {
        for s in 0..ev.slot_count {
            let now = ev.now[s];
            if !now.active {
                continue;
            }
            if first_active[s].is_nan() {
                first_active[s] = time;
            }
            if now.rate > 0.0 {
                approaching[s] = true;
            } else if approaching[s] && arrest[s].is_none() {
                arrest[s] = Some(time);
            }
        }
    };
    record(&ev, 0.0);

    while state[TIME] < t_end {
        if steps + rejected >= settings.max_steps {
            end = TransientEnd::StepLimit;
            break;
        }
        let now = state[TIME];
        let h_try = h.min(t_end - now);
        if !(h_try > 0.0) || now + h_try == now {
            return Err(BodyTransientError::StepSizeUnderflow { time: now - t });
        }
        let step = {
            let mut rhs = |z: &State| ev.derivative(z);
            dopri5_step(&mut rhs, &state, &f0, h_try)
        };
        // The last stage is the step's end: a different count of loaded points means a
        // switch of the law inside the step.
        let switched = ev.loaded_points != loaded_at_state;
        if ev.overflow {
            return Err(BodyTransientError::TooManyTracks { time: now - t });
        }
        let mut err = 0.0f64;
        for i in 0..DIM {
            let sc = absolute[i] + relative[i] * state[i].abs().max(step.y[i].abs());
            err = err.max(step.error[i].abs() / sc);
        }
        if switched {
            err /= settings.switch_tolerance_factor;
        }
        if !err.is_finite() {
            err = 1e10;
        }
        if err > 1.0 {
            rejected += 1;
            h = control.rejected(h_try, err);
            continue;
        }
        state = step.y;
        if h_try == t_end - now {
            state[TIME] = t_end;
        }
        f0 = step.dydt;
        loaded_at_state = ev.loaded_points;
        steps += 1;
        // The last stage was evaluated at the accepted state (FSAL): its tracks are there.
        record(&ev, state[TIME] - t);
        h = control.accepted(h_try, err);
    }

    // The end state with its quaternion normalised (the forces used the normalised rotation
    // throughout), and the tracks and stored energy there.
    normalize_quaternion(&mut state);
    ev.derivative(&state);
    let mut end_state = [0.0; BODY_STATE_LEN];
    end_state.copy_from_slice(&state[..BODY_STATE_LEN]);
    let tracks = (0..ev.slot_count)
        .map(|s| {
            let base = TRACKS + s * PER_TRACK;
            let (contact, track) = ev.slots[s];
            let now = ev.now[s];
            TransientTrack {
                contact,
                track,
                normal_impulse: state[base + T_PN],
                tangential_impulse: Vector3::new(
                    state[base + T_PT],
                    state[base + T_PT + 1],
                    state[base + T_PT + 2],
                ),
                normal_force_slip_integral: state[base + T_NSLIP],
                damping_dissipation: state[base + T_DAMP],
                friction_dissipation: state[base + T_FRIC],
                first_active_s: first_active[s],
                arrest_s: arrest[s],
                normal: ev.last_normal[s],
                active_at_end: now.active,
                end_penetration: if now.active { now.penetration } else { 0.0 },
                end_penetration_rate: if now.active { now.rate } else { 0.0 },
            }
        })
        .collect();
    Ok(BodyTransient {
        end,
        duration: state[TIME] - t,
        end_state,
        kinetic_energy: [kinetic_start, ev.kinetic_energy(&state)],
        stored_energy: [stored_start, ev.stored],
        damping_dissipation: state[E_DAMP],
        friction_dissipation: state[E_FRIC],
        element_dissipation: state[E_ELEM],
        gravity_work: state[W_GRAV],
        drive_work: state[W_DRIVE],
        applied_work: state[W_APPLIED],
        tracks,
        steps,
        rejected_steps: rejected,
    })
}

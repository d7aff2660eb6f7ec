//! The contact-local impulse map of one normal transient (issue 28, first part).
//!
//! From first touch (`w = 0`, approach speed `v_n > 0`) the normal and tangential motion of one
//! contact point is integrated on its own time scale, with the rest of the system frozen into an
//! effective mass and a constant external force, until the point leaves (`w` back to 0) or a
//! time limit. The law is the engine's own: IMPACT with its STEP damping ramp and clamp
//! ([`ImpactParams`], eq. 2.1-2.3) and the regularized Coulomb friction ([`FrictionParams`],
//! eq. 4.5), so a map and a resolved run of the same contact solve the same equations:
//!
//! ```text
//! m_n ẅ   = F_n − N,                     N   = max(0, k w^e + c_max STEP(w, 0, 0, d, 1) ẇ)
//! m_t v̇_t = F_t − μ(|v_t|) N v_t/|v_t|   (v_t the 1-D or 2-D slip velocity)
//! ```
//!
//! The quadratures the caller needs (impulses, damping and friction dissipation, external work,
//! `∫N|v_t| dt`) are carried as extra state components of the same Dormand–Prince 5(4) steps
//! ([`super::local_dopri5`]), under the same error control. The force is smooth between
//! `w = 0`, `w = d` and the clamp's switch (`N` reaching 0); the steps land on those points
//! (event location on a cubic Hermite interpolant, then a step of exactly that length), each
//! side using its own smooth formula, so the method keeps its order. docs/reference/models.md,
//! "Contact-local impulse map", gives the assumptions and the measured error.

use super::friction::FrictionParams;
use super::impact::ImpactParams;
use super::local_dopri5::{dopri5_step, hermite, PiControl};
use crate::field_error::FieldError;

/// The contact at first touch: effective masses, the approach and slip velocities, and the
/// external force frozen over the transient (`w = 0` at the start by definition).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactApproach {
    /// Effective mass along the contact normal, kg (`1 / (n · M⁻¹ n)` at the contact point).
    pub normal_mass: f64,
    /// Effective mass in the tangent plane, kg (equal to `normal_mass` for a point mass).
    pub tangential_mass: f64,
    /// Approach speed `ẇ` at first touch, m/s (> 0: the point moves into the surface).
    pub approach_speed: f64,
    /// Slip velocity in the tangent plane at first touch, m/s (2-D; a 1-D slip sets `[v, 0]`).
    pub slip_velocity: [f64; 2],
    /// External force along the normal, N, positive pressing into the contact (gravity's
    /// component, drive), constant over the transient.
    pub external_normal_force: f64,
    /// External force in the tangent plane, N, constant over the transient.
    pub external_tangential_force: [f64; 2],
}

/// Error control and horizon of a map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactMapSettings {
    /// Relative tolerance per step on every state component (its own scale: penetration,
    /// speeds, impulses, energies). Default 1e-10: the energy account then closes to ~1e-11 of
    /// the dissipated work (tests/engine/impact_map.rs); 1e-7 is ~3x fewer steps.
    pub relative_tolerance: f64,
    /// Horizon over which the rest of the system may be taken as frozen, s. A contact still
    /// closed at this time is reported as [`ContactEnd::TimeLimit`]: persistent, for the global
    /// integrator to keep resolving from the returned end state. Default 1e-3 s (the undamped
    /// contact of the thesis' 46 g cube at 1 m/s lasts 1.15 ms).
    pub time_limit: f64,
    /// Most step attempts (accepted and rejected) before [`ContactEnd::StepLimit`]. Default 1e6.
    pub max_steps: usize,
}

impl Default for ImpactMapSettings {
    fn default() -> Self {
        Self {
            relative_tolerance: 1e-10,
            time_limit: 1e-3,
            max_steps: 1_000_000,
        }
    }
}

/// How the transient ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactEnd {
    /// The point left the surface (`w` back to 0, moving out): the contact is open.
    Separated,
    /// Still in contact at [`ImpactMapSettings::time_limit`]: a persistent contact.
    TimeLimit,
    /// Still in contact after [`ImpactMapSettings::max_steps`] attempts.
    StepLimit,
}

/// What one transient hands back to the system: impulses, energies, wear integrals, end state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactMap {
    /// How the integration ended.
    pub end: ContactEnd,
    /// Time from first touch to the end, s (the contact duration when separated).
    pub duration: f64,
    /// Normal impulse of the contact on the point, `∫N dt`, N·s (also the wear law's `∫N dt`).
    pub normal_impulse: f64,
    /// Friction impulse on the point, `−∫μ N v_t/|v_t| dt`, N·s (opposes the slip).
    pub tangential_impulse: [f64; 2],
    /// Energy dissipated by the damping and the clamp, `∫(N − k w^e) ẇ dt` >= 0, J.
    pub damping_dissipation: f64,
    /// Energy dissipated by friction, `∫μ N |v_t| dt` >= 0, J.
    pub friction_dissipation: f64,
    /// Work of the frozen external force, `∫(F_n ẇ + F_t · v_t) dt`, J.
    pub external_work: f64,
    /// `∫N |v_t| dt`, N·m: the load times slip distance of Archard's law.
    pub normal_force_slip_integral: f64,
    /// Penetration rate at the end, m/s (negative: leaving).
    pub exit_normal_velocity: f64,
    /// Slip velocity at the end, m/s.
    pub exit_slip_velocity: [f64; 2],
    /// Penetration at the end, m (0 up to the event location when separated).
    pub end_penetration: f64,
    /// Largest penetration reached, m.
    pub max_penetration: f64,
    /// Accepted steps.
    pub steps: usize,
    /// Rejected step attempts.
    pub rejected_steps: usize,
}

impl ImpactMap {
    /// Normal coefficient of restitution `−ẇ_out / v_n`, when the contact separated.
    pub fn restitution(&self, approach_speed: f64) -> Option<f64> {
        (self.end == ContactEnd::Separated).then(|| -self.exit_normal_velocity / approach_speed)
    }
}

/// Why a map could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImpactMapError {
    /// A field of the [`ContactApproach`] breaks its rule.
    #[error("impact map approach: {0}")]
    Approach(FieldError),
    /// A field of the [`ImpactParams`] breaks its rule.
    #[error("impact law: {0}")]
    Impact(FieldError),
    /// A field of the [`FrictionParams`] breaks its rule.
    #[error("friction law: {0}")]
    Friction(FieldError),
    /// A field of the [`ImpactMapSettings`] breaks its rule.
    #[error("impact map settings: {0}")]
    Settings(FieldError),
    /// The step size fell below the resolution of the time (a non-finite state).
    #[error("impact map step size underflow at t = {time} s")]
    StepSizeUnderflow {
        /// Time since first touch, s.
        time: f64,
    },
}

impl ImpactMapError {
    /// The offending field's name, for input errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            Self::Approach(e) | Self::Impact(e) | Self::Friction(e) | Self::Settings(e) => {
                Some(&e.field)
            }
            Self::StepSizeUnderflow { .. } => None,
        }
    }
}

impl ContactApproach {
    /// A point of mass `mass` (both effective masses) meeting the surface head-on at `speed`,
    /// with no slip and no external force.
    pub fn head_on(mass: f64, speed: f64) -> Self {
        Self {
            normal_mass: mass,
            tangential_mass: mass,
            approach_speed: speed,
            slip_velocity: [0.0, 0.0],
            external_normal_force: 0.0,
            external_tangential_force: [0.0, 0.0],
        }
    }

    /// Checks every field: masses finite and > 0, approach speed finite and > 0, the rest finite.
    pub fn validate(&self) -> Result<(), FieldError> {
        for (field, x) in [
            ("normal_mass", self.normal_mass),
            ("tangential_mass", self.tangential_mass),
            ("approach_speed", self.approach_speed),
        ] {
            positive(field, x)?;
        }
        let finite = [
            ("slip_velocity", self.slip_velocity),
            ("external_tangential_force", self.external_tangential_force),
            ("external_normal_force", [self.external_normal_force, 0.0]),
        ];
        for (field, [x, y]) in finite {
            if !(x.is_finite() && y.is_finite()) {
                return Err(FieldError::new(field, "must be finite"));
            }
        }
        Ok(())
    }
}

/// `x` finite and > 0, or the field's error.
pub(super) fn positive(field: &str, x: f64) -> Result<(), FieldError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(FieldError::new(
            field,
            format!("must be a finite number > 0, got {x}"),
        ))
    }
}

/// A relative tolerance `r`: finite and in (0, 1), or the field's error.
pub(super) fn relative_tolerance(field: &str, r: f64) -> Result<(), FieldError> {
    if r.is_finite() && r > 0.0 && r < 1.0 {
        Ok(())
    } else {
        Err(FieldError::new(
            field,
            format!("must be a finite number in (0, 1), got {r}"),
        ))
    }
}

impl ImpactMapSettings {
    /// Checks the tolerance (finite, in (0, 1)), the time limit (finite, > 0) and the step count.
    pub fn validate(&self) -> Result<(), FieldError> {
        relative_tolerance("relative_tolerance", self.relative_tolerance)?;
        positive("time_limit", self.time_limit)?;
        if self.max_steps == 0 {
            return Err(FieldError::new("max_steps", "must be at least 1"));
        }
        Ok(())
    }
}

// State components: penetration, its rate, slip velocity, then the quadratures. They are the
// first `WALL_DIM` components of every map's state (`physics::supported_impact_map` appends
// its supports' to them).
pub(super) const W: usize = 0;
pub(super) const WDOT: usize = 1;
pub(super) const VX: usize = 2;
pub(super) const VY: usize = 3;
pub(super) const PN: usize = 4;
pub(super) const PTX: usize = 5;
pub(super) const PTY: usize = 6;
const E_DAMP: usize = 7;
const E_FRIC: usize = 8;
const W_EXT: usize = 9;
const N_SLIP: usize = 10;
pub(super) const WALL_DIM: usize = 11;
const DIM: usize = WALL_DIM;
type State = [f64; DIM];

/// Which smooth piece of the force law applies: the damping ramp or full damping, and whether
/// the clamp holds `N` at zero. Each piece's formula is used a little past its boundary, up to
/// the event the step lands on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Piece {
    on_ramp: bool,
    clamped: bool,
}

/// A switch of the force law, or the turning point (recorded, nothing switches).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Event {
    Separation,
    RampEnd,
    RampStart,
    Clamp,
    Release,
    Turning,
}

const EVENTS: [Event; 6] = [
    Event::Separation,
    Event::RampEnd,
    Event::RampStart,
    Event::Clamp,
    Event::Release,
    Event::Turning,
];

/// The contact's normal law on its smooth pieces (eq. 2.1-2.3 with the STEP ramp and clamp).
#[derive(Clone, Copy)]
pub(super) struct NormalLaw<'a> {
    pub(super) impact: &'a ImpactParams,
}

impl NormalLaw<'_> {
    /// Damping coefficient of `piece` at `w`, N·s/m.
    #[inline]
    fn damping(&self, piece: Piece, w: f64) -> f64 {
        let p = self.impact;
        if piece.on_ramp {
            p.max_damping * p.step.unit(w / p.full_damping_depth)
        } else {
            p.max_damping
        }
    }

    /// Unclamped normal force `k w^e + c ẇ` of `piece`, N.
    #[inline]
    fn unclamped_force(&self, piece: Piece, w: f64, wdot: f64) -> f64 {
        self.impact.elastic_force(w) + self.damping(piece, w) * wdot
    }

    /// The elastic force `k w^e` and the normal force `N` of `piece` at `(w, ẇ)`, N.
    #[inline]
    pub(super) fn forces(&self, piece: Piece, w: f64, wdot: f64) -> (f64, f64) {
        let spring = self.impact.elastic_force(w);
        let normal = if piece.clamped {
            0.0
        } else {
            spring + self.damping(piece, w) * wdot
        };
        (spring, normal)
    }

    /// The event's function at `(w, ẇ)`: >= 0 on the piece's side, < 0 past the event.
    /// `None` where the event cannot happen from `piece` (or, for the turning point, from a
    /// step that starts leaving).
    fn event_value(&self, event: Event, piece: Piece, w: f64, wdot: f64) -> Option<f64> {
        let d = self.impact.full_damping_depth;
        match event {
            Event::Separation => (piece.on_ramp || d == 0.0).then_some(w),
            Event::RampEnd => piece.on_ramp.then_some(d - w),
            Event::RampStart => (!piece.on_ramp && d > 0.0).then_some(w - d),
            Event::Clamp => (!piece.clamped).then(|| self.unclamped_force(piece, w, wdot)),
            Event::Release => piece.clamped.then(|| -self.unclamped_force(piece, w, wdot)),
            Event::Turning => Some(wdot),
        }
    }
}

struct LocalContact<'a> {
    approach: &'a ContactApproach,
    law: NormalLaw<'a>,
    friction: &'a FrictionParams,
    /// `dμ/dv` at zero slip: `μ(v)/v` there, the regularized law's viscous limit.
    mu_slope_at_rest: f64,
}

/// The touching contact's forces at `(w, ẇ)` and slip `(vx, vy)` on `piece`: the normal law's
/// spring part and total, and the regularized friction `−N μ(|v|)/|v| v` (the rest slope at
/// zero slip). Shared with [`super::supported_impact_map`], whose wall is this contact.
pub(super) struct WallForces {
    pub spring: f64,
    pub normal: f64,
    pub friction: [f64; 2],
    pub mu: f64,
    pub speed: f64,
}

impl WallForces {
    pub fn at(law: &NormalLaw, f: &FrictionParams, slope: f64, p: Piece, y: [f64; 4]) -> Self {
        let [w, wdot, vx, vy] = y;
        let (spring, normal) = law.forces(p, w, wdot);
        let speed = vx.hypot(vy);
        let mu = f.coefficient(speed);
        let mu_per_speed = if speed > 0.0 { mu / speed } else { slope };
        let friction = [-normal * mu_per_speed * vx, -normal * mu_per_speed * vy];
        Self {
            spring,
            normal,
            friction,
            mu,
            speed,
        }
    }

    /// Writes the touching contact's quadrature rates into `d` (impulses, damping and friction
    /// dissipation, the external forces' work at rates `wdot` and `v`, `N|v_t|`).
    pub fn quadratures(&self, a: &ContactApproach, wdot: f64, v: [f64; 2], d: &mut [f64]) {
        let [ftx, fty] = a.external_tangential_force;
        d[PN] = self.normal;
        [d[PTX], d[PTY]] = self.friction;
        d[E_DAMP] = (self.normal - self.spring) * wdot;
        d[E_FRIC] = self.normal * self.mu * self.speed;
        d[W_EXT] = a.external_normal_force * wdot + ftx * v[0] + fty * v[1];
        d[N_SLIP] = self.normal * self.speed;
    }
}

impl LocalContact<'_> {
    fn derivative(&self, piece: Piece, y: &State) -> State {
        let a = self.approach;
        let (wdot, vx, vy) = (y[WDOT], y[VX], y[VY]);
        let (law, rest) = (&self.law, self.mu_slope_at_rest);
        let f = WallForces::at(law, self.friction, rest, piece, [y[W], wdot, vx, vy]);
        let [ftx, fty] = a.external_tangential_force;
        let mut d = [0.0; DIM];
        d[W] = wdot;
        d[WDOT] = (a.external_normal_force - f.normal) / a.normal_mass;
        d[VX] = (ftx + f.friction[0]) / a.tangential_mass;
        d[VY] = (fty + f.friction[1]) / a.tangential_mass;
        f.quadratures(a, wdot, [vx, vy], &mut d);
        d
    }
}

/// The root in `[0, 1]` of `g` with `g(0) >= 0 > g(1)` (Illinois regula falsi); 0 when
/// `g(0) < 0` already (the event sits at the step's start).
fn first_crossing(mut g: impl FnMut(f64) -> f64, g0: f64, g1: f64) -> f64 {
    if g0 < 0.0 {
        return 0.0;
    }
    let (mut a, mut fa, mut b, mut fb) = (0.0, g0, 1.0, g1);
    let mut side = 0;
    for _ in 0..60 {
        let c = (a * fb - b * fa) / (fb - fa);
        let fc = g(c);
        if fc >= 0.0 {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
        if b - a < 1e-13 {
            break;
        }
    }
    b
}

/// Error-test scales of a transient from `approach`: the undamped peak penetration at the
/// approach speed (or the static one under the pressing force), the larger of the approach
/// and slip speeds, and the momentum and kinetic energy at that speed.
pub(super) struct Scales {
    pub(super) penetration: f64,
    pub(super) speed: f64,
    pub(super) momentum: f64,
    pub(super) energy: f64,
}

impl Scales {
    pub(super) fn of(approach: &ContactApproach, impact: &ImpactParams) -> Self {
        let speed = approach
            .approach_speed
            .max(approach.slip_velocity[0].hypot(approach.slip_velocity[1]));
        let mass = approach.normal_mass.max(approach.tangential_mass);
        let e = impact.exponent;
        let penetration = ((e + 1.0) * approach.normal_mass * approach.approach_speed.powi(2)
            / (2.0 * impact.stiffness))
            .powf(1.0 / (e + 1.0))
            .max(impact.static_penetration(approach.external_normal_force.abs()));
        Self {
            penetration,
            speed,
            momentum: mass * speed,
            energy: 0.5 * mass * speed * speed,
        }
    }

    /// Error-control scales of a map's state: the wall's components by their kind, the rest
    /// (quadratures of energy, and whatever a longer state appends) by the energy scale.
    pub(super) fn state<const D: usize>(&self) -> [f64; D] {
        let mut scale = [self.energy; D];
        scale[W] = self.penetration;
        scale[WDOT..=VY].fill(self.speed);
        scale[PN..=PTY].fill(self.momentum);
        scale
    }

    /// The first step's size: 1e-3 of the time to the undamped peak, and 0.1 of `m_n/c_max`.
    pub(super) fn first_step(&self, approach: &ContactApproach, impact: &ImpactParams) -> f64 {
        let mut h = 1e-3 * self.penetration / approach.approach_speed;
        if impact.max_damping > 0.0 {
            h = h.min(0.1 * approach.normal_mass / impact.max_damping);
        }
        h
    }
}

/// The end of a transient [`integrate`] ran: how, when, the state, the steps.
pub(super) struct Transient<const D: usize> {
    pub(super) end: ContactEnd,
    pub(super) duration: f64,
    pub(super) y: [f64; D],
    pub(super) max_penetration: f64,
    pub(super) steps: usize,
    pub(super) rejected: usize,
}

impl<const D: usize> Transient<D> {
    /// The touching contact's map from the transient's end (its first [`WALL_DIM`] components).
    pub(super) fn wall_map(&self) -> ImpactMap {
        let y = &self.y;
        ImpactMap {
            end: self.end,
            duration: self.duration,
            normal_impulse: y[PN],
            tangential_impulse: [y[PTX], y[PTY]],
            damping_dissipation: y[E_DAMP],
            friction_dissipation: y[E_FRIC],
            external_work: y[W_EXT],
            normal_force_slip_integral: y[N_SLIP],
            exit_normal_velocity: y[WDOT],
            exit_slip_velocity: [y[VX], y[VY]],
            end_penetration: y[W],
            max_penetration: self.max_penetration,
            steps: self.steps,
            rejected_steps: self.rejected,
        }
    }
}

/// A map's state at first touch: the approach and slip velocities, nothing integrated yet.
pub(super) fn start_state<const D: usize>(approach: &ContactApproach) -> [f64; D] {
    let mut y0 = [0.0; D];
    y0[WDOT] = approach.approach_speed;
    [y0[VX], y0[VY]] = approach.slip_velocity;
    y0
}

/// Integrates a transient whose components [`W`] and [`WDOT`] are the contact's penetration
/// and its rate (the events of `law` are read on them), from `y0` (`w = 0`) with `derivative`
/// on each piece of the law, under the relative tolerance against `scale` per component, to
/// separation or the settings' limits.
pub(super) fn integrate<const D: usize>(
    law: NormalLaw<'_>,
    settings: &ImpactMapSettings,
    y0: [f64; D],
    scale: &[f64; D],
    first_step: f64,
    derivative: impl Fn(Piece, &[f64; D]) -> [f64; D],
) -> Result<Transient<D>, ImpactMapError> {
    let rtol = settings.relative_tolerance;
    let mut piece = Piece {
        on_ramp: law.impact.full_damping_depth > 0.0,
        clamped: false,
    };
    let mut y = y0;
    let mut f0 = derivative(piece, &y);
    let mut t = 0.0;
    let mut h = first_step;
    let (mut steps, mut rejected, mut max_penetration) = (0usize, 0usize, 0.0f64);
    let mut control = PiControl::default();
    // Just landed on the turning point (ẇ there is 0 up to the location's residual, either sign).
    let mut at_turning = false;
    let mut end = ContactEnd::TimeLimit;

    loop {
        if t >= settings.time_limit {
            break;
        }
        if steps + rejected >= settings.max_steps {
            end = ContactEnd::StepLimit;
            break;
        }
        let h_try = h.min(settings.time_limit - t);
        if !(h_try > 0.0) || t + h_try == t {
            return Err(ImpactMapError::StepSizeUnderflow { time: t });
        }
        let mut rhs = |z: &[f64; D]| derivative(piece, z);
        let step = dopri5_step(&mut rhs, &y, &f0, h_try);
        let mut err = 0.0f64;
        for i in 0..D {
            let sc = rtol * scale[i].max(y[i].abs()).max(step.y[i].abs());
            err = err.max(step.error[i].abs() / sc);
        }
        if !err.is_finite() {
            err = 1e10;
        }
        if err > 1.0 {
            rejected += 1;
            h = control.rejected(h_try, err);
            continue;
        }
        // Accepted by the error test: does a switch of the law lie inside it?
        let (w0, wd0, a0) = (y[W], y[WDOT], f0[WDOT]);
        let (w1, wd1, a1) = (step.y[W], step.y[WDOT], step.dydt[WDOT]);
        let mut first: Option<(f64, Event)> = None;
        for event in EVENTS {
            if event == Event::Turning && (wd0 <= 0.0 || at_turning) {
                continue;
            }
            let Some(g1) = law.event_value(event, piece, w1, wd1) else {
                continue;
            };
            if g1 >= 0.0 {
                continue;
            }
            let g0 = law.event_value(event, piece, w0, wd0).unwrap_or(0.0);
            let at = |theta: f64| {
                let w = hermite(w0, wd0, w1, wd1, h_try, theta);
                let wd = hermite(wd0, a0, wd1, a1, h_try, theta);
                law.event_value(event, piece, w, wd).unwrap_or(0.0)
            };
            let theta = first_crossing(at, g0, g1);
            if first.is_none_or(|(th, _)| theta < th) {
                first = Some((theta, event));
            }
        }
        let landed = match first {
            None => {
                y = step.y;
                f0 = step.dydt;
                t += h_try;
                None
            }
            Some((theta, event)) => {
                let h_event = theta * h_try;
                if h_event > 0.0 && t + h_event > t {
                    let to_event = dopri5_step(&mut rhs, &y, &f0, h_event);
                    y = to_event.y;
                    f0 = to_event.dydt;
                    t += h_event;
                }
                Some(event)
            }
        };
        steps += 1;
        max_penetration = max_penetration.max(y[W]);
        h = control.accepted(h_try, err);
        at_turning = landed == Some(Event::Turning);
        let Some(event) = landed else {
            continue;
        };
        match event {
            Event::Separation => {
                end = ContactEnd::Separated;
                break;
            }
            Event::RampEnd => piece.on_ramp = false,
            Event::RampStart => piece.on_ramp = true,
            Event::Clamp => piece.clamped = true,
            Event::Release => piece.clamped = false,
            Event::Turning => {}
        }
        f0 = derivative(piece, &y);
    }
    Ok(Transient {
        end,
        duration: t,
        y,
        max_penetration,
        steps,
        rejected,
    })
}

/// The map of one transient: integrates the contact from first touch to separation or the
/// time limit and returns its impulses, energies, wear integrals and end state.
pub fn impact_map(
    approach: &ContactApproach,
    impact: &ImpactParams,
    friction: &FrictionParams,
    settings: &ImpactMapSettings,
) -> Result<ImpactMap, ImpactMapError> {
    approach.validate().map_err(ImpactMapError::Approach)?;
    impact.validate().map_err(ImpactMapError::Impact)?;
    friction.validate().map_err(ImpactMapError::Friction)?;
    settings.validate().map_err(ImpactMapError::Settings)?;
    let contact = LocalContact {
        approach,
        law: NormalLaw { impact },
        friction,
        mu_slope_at_rest: friction.coefficient_derivative(0.0),
    };
    let sc = Scales::of(approach, impact);
    let run = integrate(
        contact.law,
        settings,
        start_state(approach),
        &sc.state(),
        sc.first_step(approach, impact),
        |piece, y| contact.derivative(piece, y),
    )?;
    Ok(run.wall_map())
}

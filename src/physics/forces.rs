//! Force elements: gravity is handled by the system; here are the point-to-point and
//! point force elements of the launcher model (thesis 6.5) and a penalty bushing used for
//! lock and cylindrical joints.

use super::body::BodyFrame;
use super::step::StepKind;
use nalgebra::{Point3, UnitQuaternion, Vector3};

/// A point fixed in a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attachment {
    /// Body index in the system.
    pub body: usize,
    /// Point in that body's frame, m.
    pub point: Point3<f64>,
}

/// Linear coil spring-damper between two points (ADAMS SPRINGDAMPER):
/// `F = -k (L - L0) - c dL/dt + F0`, positive pushes the points apart.
#[derive(Debug, Clone, PartialEq)]
pub struct SpringDamper {
    /// Name for reports.
    pub name: String,
    /// First end.
    pub a: Attachment,
    /// Second end.
    pub b: Attachment,
    /// Stiffness k, N/m.
    pub stiffness: f64,
    /// Damping c, N·s/m.
    pub damping: f64,
    /// Free length L0, m.
    pub free_length: f64,
    /// Preload F0 at L = L0, N (positive pushes apart).
    pub preload: f64,
}

/// One-sided spring (thesis 6.5 rear leaf spring): the tip on body `b` pushes body `a`'s point
/// along `direction` (in b's frame) once the deflection `δ = (p_b - p_a)·n - gap` is positive,
/// engaged through a smooth step over `transition` so the force is continuous:
/// `F = STEP(δ, 0, 0, transition, 1) · max(0, F0 + k δ + c dδ/dt)`.
#[derive(Debug, Clone, PartialEq)]
pub struct OneSidedSpring {
    /// Name for reports.
    pub name: String,
    /// Pushed point (e.g. on the rear shoe).
    pub a: Attachment,
    /// Spring tip (e.g. on the rail).
    pub b: Attachment,
    /// Push direction in b's frame (unit).
    pub direction: Vector3<f64>,
    /// Stiffness k, N/m.
    pub stiffness: f64,
    /// Damping c, N·s/m.
    pub damping: f64,
    /// Force at zero deflection once engaged, N.
    pub preload: f64,
    /// Clearance before engagement, m (may be larger than the static deflection: then the
    /// spring is free when static, thesis 6.3.1).
    pub engagement_gap: f64,
    /// Width of the smooth engagement, m.
    pub transition: f64,
    /// Step shape.
    pub step: StepKind,
}

impl OneSidedSpring {
    /// Elastic energy at deflection `delta` (m), J: `∫₀^δ STEP(s) (F0 + k s) ds`, the exact
    /// potential of the engaged force (4 panels of 5-point Gauss-Legendre over the smooth
    /// engagement: exact for the cubic step, within 1e-9 relative for the cycloidal one; closed
    /// form beyond).
    pub fn potential(&self, delta: f64) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        let elastic = |x: f64| self.preload + self.stiffness * x;
        let ramp_end = delta.min(self.transition.max(0.0));
        let mut energy = 0.0;
        if ramp_end > 0.0 {
            const NODES: [f64; 5] = [
                -0.906_179_845_938_664,
                -0.538_469_310_105_683,
                0.0,
                0.538_469_310_105_683,
                0.906_179_845_938_664,
            ];
            const WEIGHTS: [f64; 5] = [
                0.236_926_885_056_189,
                0.478_628_670_499_366,
                0.568_888_888_888_889,
                0.478_628_670_499_366,
                0.236_926_885_056_189,
            ];
            const PANELS: usize = 4;
            let half = 0.5 * ramp_end / PANELS as f64;
            for panel in 0..PANELS {
                let mid = (2 * panel + 1) as f64 * half;
                for (x, wq) in NODES.iter().zip(WEIGHTS) {
                    let s = mid + half * x;
                    let step = self.step.eval(s, 0.0, 0.0, self.transition, 1.0);
                    energy += wq * half * step * elastic(s);
                }
            }
        }
        if delta > ramp_end {
            energy += self.preload * (delta - ramp_end)
                + 0.5 * self.stiffness * (delta * delta - ramp_end * ramp_end);
        }
        energy
    }
}

/// Constant force at a point, given in the frame of body `a` (a spring whose deflection does
/// not change, e.g. the double-barrel springs of thesis 6.5), reacted at `reaction` if given.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstantForce {
    /// Name for reports.
    pub name: String,
    /// Where the force acts.
    pub a: Attachment,
    /// Force in a's frame, N.
    pub force_body: Vector3<f64>,
    /// Where the opposite force acts, if on a modelled body.
    pub reaction: Option<Attachment>,
}

/// Penalty bushing between joint frames on two bodies. Stiffness per joint axis (of b's joint
/// frame): zero stiffness frees that axis. A lock has all six stiff; a cylindrical joint along
/// joint z has x, y translations and x, y rotations stiff.
#[derive(Debug, Clone, PartialEq)]
pub struct Bushing {
    /// Name for reports.
    pub name: String,
    /// Joint origin on body a.
    pub a: Attachment,
    /// Joint origin on body b.
    pub b: Attachment,
    /// Joint frame orientation relative to b's body frame (also used for a at assembly).
    pub frame_b: UnitQuaternion<f64>,
    /// Joint frame orientation relative to a's body frame.
    pub frame_a: UnitQuaternion<f64>,
    /// Translational stiffness along joint x, y, z, N/m.
    pub translational_stiffness: Vector3<f64>,
    /// Translational damping, N·s/m.
    pub translational_damping: Vector3<f64>,
    /// Rotational stiffness about joint x, y, z, N·m/rad.
    pub rotational_stiffness: Vector3<f64>,
    /// Rotational damping, N·m·s/rad.
    pub rotational_damping: Vector3<f64>,
}

/// Any force element.
#[derive(Debug, Clone, PartialEq)]
pub enum ForceElement {
    /// Coil spring-damper.
    SpringDamper(SpringDamper),
    /// One-sided spring with engagement gap.
    OneSidedSpring(OneSidedSpring),
    /// Constant point force.
    ConstantForce(ConstantForce),
    /// Penalty joint.
    Bushing(Bushing),
}

/// Force and torque (about the centre of mass), world frame, accumulated per body.
pub type Wrench = (Vector3<f64>, Vector3<f64>);

/// What a force element stores and exchanges at one instant (the energy account, SPEC §2).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ElementPower {
    /// Elastic energy stored, J.
    pub potential: f64,
    /// Power dissipated (damping, and a one-sided spring's clamp), W (>= 0).
    pub dissipation: f64,
    /// Power of applied loads on both ends (constant forces), W.
    pub applied: f64,
}

#[inline]
pub(crate) fn apply(
    wrenches: &mut [Wrench],
    frames: &[BodyFrame],
    body: usize,
    point: &Point3<f64>,
    force: Vector3<f64>,
) {
    let r = point.coords - frames[body].position;
    wrenches[body].0 += force;
    wrenches[body].1 += r.cross(&force);
}

impl ForceElement {
    /// Name for reports and diagnostics.
    pub fn name(&self) -> &str {
        match self {
            ForceElement::SpringDamper(s) => &s.name,
            ForceElement::OneSidedSpring(s) => &s.name,
            ForceElement::ConstantForce(s) => &s.name,
            ForceElement::Bushing(s) => &s.name,
        }
    }

    /// The bodies this element acts on: its first end, and its second end or reaction (None
    /// for a constant force without a modelled reaction).
    pub fn bodies(&self) -> [Option<usize>; 2] {
        match self {
            ForceElement::SpringDamper(s) => [Some(s.a.body), Some(s.b.body)],
            ForceElement::OneSidedSpring(s) => [Some(s.a.body), Some(s.b.body)],
            ForceElement::ConstantForce(s) => [Some(s.a.body), s.reaction.map(|r| r.body)],
            ForceElement::Bushing(s) => [Some(s.a.body), Some(s.b.body)],
        }
    }

    /// Adds this element's forces to `wrenches`; returns its potential energy, J.
    pub fn accumulate(&self, frames: &[BodyFrame], wrenches: &mut [Wrench]) -> f64 {
        self.accumulate_with_power(frames, wrenches).potential
    }

    /// Adds this element's forces to `wrenches`; returns its stored energy and the power it
    /// dissipates or applies. Each elastic force is the exact gradient of the potential returned
    /// (for a body `b` that does not rotate: the rail and the ground in the reference models),
    /// so `potential + ∫ dissipation - ∫ applied` changes only by the work done on the ends.
    pub fn accumulate_with_power(
        &self,
        frames: &[BodyFrame],
        wrenches: &mut [Wrench],
    ) -> ElementPower {
        match self {
            ForceElement::SpringDamper(s) => {
                let pa = frames[s.a.body].to_world(&s.a.point);
                let pb = frames[s.b.body].to_world(&s.b.point);
                let d = pa - pb;
                let len = d.norm();
                if len < 1e-12 {
                    return ElementPower::default();
                }
                let u = d / len;
                let rate = (frames[s.a.body].point_velocity(&pa)
                    - frames[s.b.body].point_velocity(&pb))
                .dot(&u);
                let f = -s.stiffness * (len - s.free_length) - s.damping * rate + s.preload;
                apply(wrenches, frames, s.a.body, &pa, u * f);
                apply(wrenches, frames, s.b.body, &pb, -u * f);
                ElementPower {
                    potential: 0.5 * s.stiffness * (len - s.free_length).powi(2)
                        - s.preload * (len - s.free_length),
                    dissipation: s.damping * rate * rate,
                    applied: 0.0,
                }
            }
            ForceElement::OneSidedSpring(s) => {
                let pa = frames[s.a.body].to_world(&s.a.point);
                let pb = frames[s.b.body].to_world(&s.b.point);
                let n = frames[s.b.body].rotation * s.direction;
                let delta = (pb - pa).dot(&n) - s.engagement_gap;
                if delta <= 0.0 {
                    return ElementPower::default();
                }
                let rate = (frames[s.b.body].point_velocity(&pb)
                    - frames[s.a.body].point_velocity(&pa))
                .dot(&n);
                let engage = s.step.eval(delta, 0.0, 0.0, s.transition, 1.0);
                let f = engage * (s.preload + s.stiffness * delta + s.damping * rate).max(0.0);
                apply(wrenches, frames, s.a.body, &pa, n * f);
                apply(wrenches, frames, s.b.body, &pb, -n * f);
                let elastic = engage * (s.preload + s.stiffness * delta);
                ElementPower {
                    potential: s.potential(delta),
                    dissipation: (f - elastic) * rate,
                    applied: 0.0,
                }
            }
            ForceElement::ConstantForce(s) => {
                let pa = frames[s.a.body].to_world(&s.a.point);
                let f = frames[s.a.body].rotation * s.force_body;
                apply(wrenches, frames, s.a.body, &pa, f);
                let mut applied = f.dot(&frames[s.a.body].point_velocity(&pa));
                if let Some(r) = &s.reaction {
                    let pr = frames[r.body].to_world(&r.point);
                    apply(wrenches, frames, r.body, &pr, -f);
                    applied -= f.dot(&frames[r.body].point_velocity(&pr));
                }
                ElementPower {
                    potential: 0.0,
                    dissipation: 0.0,
                    applied,
                }
            }
            ForceElement::Bushing(s) => {
                let fa = &frames[s.a.body];
                let fb = &frames[s.b.body];
                let pa = fa.to_world(&s.a.point);
                let pb = fb.to_world(&s.b.point);
                let rj_b = fb.rotation * s.frame_b;
                let rj_a = fa.rotation * s.frame_a;
                let d = rj_b.inverse() * (pa - pb);
                let ddot = rj_b.inverse() * (fa.point_velocity(&pa) - fb.point_velocity(&pb));
                let f_local = -s.translational_stiffness.component_mul(&d)
                    - s.translational_damping.component_mul(&ddot);
                let f = rj_b * f_local;
                apply(wrenches, frames, s.a.body, &pa, f);
                apply(wrenches, frames, s.b.body, &pb, -f);
                let q_rel = rj_b.inverse() * rj_a;
                let sign = if q_rel.w < 0.0 { -1.0 } else { 1.0 };
                let (w, v) = (
                    sign * q_rel.w,
                    sign * Vector3::new(q_rel.i, q_rel.j, q_rel.k),
                );
                let theta = 2.0 * v;
                let wrel = rj_b.inverse() * (fa.angular_velocity - fb.angular_velocity);
                // Exact gradient of U = ½ θᵀ K θ with θ = 2 vec(q): θ' = w Ω + Ω × v, so the
                // torque doing −dU/dt is −(w Kθ + v × Kθ) (−Kθ alone creates energy at third
                // order in the angle).
                let k_theta = s.rotational_stiffness.component_mul(&theta);
                let t_local =
                    -(k_theta * w + v.cross(&k_theta)) - s.rotational_damping.component_mul(&wrel);
                let t = rj_b * t_local;
                wrenches[s.a.body].1 += t;
                wrenches[s.b.body].1 -= t;
                ElementPower {
                    potential: 0.5
                        * (s.translational_stiffness.dot(&d.component_mul(&d))
                            + s.rotational_stiffness.dot(&theta.component_mul(&theta))),
                    dissipation: ddot.dot(&s.translational_damping.component_mul(&ddot))
                        + wrel.dot(&s.rotational_damping.component_mul(&wrel)),
                    applied: 0.0,
                }
            }
        }
    }
}

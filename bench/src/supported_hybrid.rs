//! The impact-split study's third hybrid: at a touch, the supported impulse map
//! (`physics::supported_impact_map`: the touching wall's transient with the body's other
//! pressed tracks, the floor, as rigid supports) over the same 20 µs as the frozen-rest map
//! and the body transient, its end state handed to the global integrator.

use super::body_hybrid::GroupResult;
use super::*;
use nalgebra::Point3;
use railwear::physics::body::{frame_from_state, BodyKind};
use railwear::physics::contact::TrackState;
use railwear::physics::friction::FrictionParams;
use railwear::physics::impact_map::{ContactApproach, ImpactMapSettings};
use railwear::physics::supported_impact_map::{
    supported_impact_map, Support, SupportedImpactMap, MAX_SUPPORTS,
};

/// One touch's supported map and the start it hands over.
pub(crate) struct SupportedHybrid {
    /// Time and system state at the end of the map.
    pub(crate) start: (f64, Vec<f64>),
    pub(crate) map: SupportedImpactMap,
    /// `∫N|v_slip| dt` of the map (wall and supports) plus the tracks that are not supports
    /// frozen over the map, N·m.
    pub(crate) normal_slip: f64,
    /// Wall-clock time of one map, s (the median of [`TIMED_REPEATS`]).
    pub(crate) wall_s: f64,
    /// This thread's CPU time over the [`TIMED_REPEATS`] evaluations, s (10 ms ticks).
    pub(crate) cpu_repeats_s: Option<f64>,
    /// The body's weight times the map's duration, N·s.
    pub(crate) weight_impulse: f64,
}

/// Evaluations of each map for its time (a map takes tens of µs: many repeats for the ticks).
pub(crate) const TIMED_REPEATS: usize = 200;

/// Two track normals closer than this cosine are one support (the same face of the tube).
const SAME_NORMAL: f64 = 0.999;

/// The supported map of `track`'s touch at the system state `y` at `t` over `horizon_s`: the
/// body's translational mass (a flat landing, as the frozen-rest map), the body's other tracks
/// with a normal force and a normal off the wall's as supports (tracks on one normal merged,
/// force-weighted), the rest frozen into the external force with gravity and the frame's
/// inertia; its velocity change applied to the body, its displacement to the body's position
/// (the wall penetration set to the map's), the rotation frozen (`translating`: the supports
/// without the rotation's velocity offset). None when the body is not
/// dynamic or the map fails (printed).
pub(crate) fn supported_hybrid_start(
    model: &BuiltModel,
    t: f64,
    y: &[f64],
    track: &TrackState,
    horizon_s: f64,
    translating: bool,
    relative_tolerance: f64,
) -> Option<SupportedHybrid> {
    let system = &model.system;
    let c = &system.contacts[track.contact as usize];
    let BodyKind::Dynamic { offset } = system.bodies[c.body_a].kind else {
        return None;
    };
    let mass = system.bodies[c.body_a].mass.mass;
    let n = track.normal;
    let p = track.point;
    let a = frame_from_state(y, offset);
    let mut ws = system.workspace();
    let mut surface_velocity = |body: usize, time: f64, point: &Point3<f64>| {
        system.frames(time, y, &mut ws);
        ws.frames[body].point_velocity(point)
    };
    let dt = 1e-7;
    let wall_acceleration = (surface_velocity(c.body_b, t + dt, &p)
        - surface_velocity(c.body_b, t - dt, &p))
        / (2.0 * dt);
    let wall_velocity = surface_velocity(c.body_b, t, &p);
    let v_rel = a.point_velocity(&p) - wall_velocity;
    let approach_speed = -n.dot(&v_rel);
    let slip = v_rel - n * n.dot(&v_rel);
    let e1 = slip.try_normalize(0.0).unwrap_or_else(|| {
        n.cross(&Vector3::x())
            .try_normalize(1e-9)
            .unwrap_or_else(|| n.cross(&Vector3::y()).normalize())
    });
    let e2 = n.cross(&e1);
    let local = |v: &Vector3<f64>| [-n.dot(v), e1.dot(v), e2.dot(v)];
    let world = |l: [f64; 3]| -n * l[0] + e1 * l[1] + e2 * l[2];

    // The body's other tracks: supports (pressed, off the wall's normal) or frozen.
    let mut others: Vec<TrackState> = Vec::new();
    let mut ws2 = system.workspace();
    system.tracks(t, y, &mut ws2, &mut |o| {
        if (o.contact, o.track) != (track.contact, track.track)
            && system.contacts[o.contact as usize].body_a == c.body_a
        {
            others.push(*o);
        }
    });
    let no_friction = FrictionParams {
        mu_static: 0.0,
        mu_dynamic: 0.0,
        ..FrictionParams::thesis_table_5_2()
    };
    // (normal, Σ N, Σ N·offset, friction) per support.
    let mut groups: Vec<(Vector3<f64>, f64, Vector3<f64>, FrictionParams)> = Vec::new();
    let mut frozen = Vector3::zeros();
    let mut frozen_normal_slip = 0.0;
    for o in &others {
        let oc = &system.contacts[o.contact as usize];
        let friction = *oc.friction.as_ref().unwrap_or(&no_friction);
        let pressed = o.normal_force > 0.0 && o.normal.dot(&n).abs() < SAME_NORMAL;
        let offset_v =
            a.point_velocity(&o.point) - surface_velocity(oc.body_b, t, &o.point) - v_rel;
        let group = groups
            .iter()
            .position(|g| g.0.dot(&o.normal) > SAME_NORMAL && g.3 == friction);
        match (pressed, group) {
            (true, Some(i)) => {
                groups[i].1 += o.normal_force;
                groups[i].2 += offset_v * o.normal_force;
            }
            (true, None) if groups.len() < MAX_SUPPORTS => {
                groups.push((
                    o.normal,
                    o.normal_force,
                    offset_v * o.normal_force,
                    friction,
                ));
            }
            _ => {
                frozen += o.force;
                frozen_normal_slip += o.normal_force * o.slip_speed;
            }
        }
    }
    let supports: Vec<Support> = groups
        .iter()
        .map(|(normal, load, weighted, friction)| Support {
            normal: local(normal),
            velocity_offset: if translating {
                [0.0; 3]
            } else {
                local(&(weighted / *load))
            },
            friction: *friction,
        })
        .collect();
    let external = system.gravity * mass + frozen - wall_acceleration * mass;
    let ext = local(&external);
    let approach = ContactApproach {
        normal_mass: mass,
        tangential_mass: mass,
        approach_speed,
        slip_velocity: [slip.norm(), 0.0],
        external_normal_force: ext[0],
        external_tangential_force: [ext[1], ext[2]],
    };
    let friction = c.friction.as_ref().unwrap_or(&no_friction);
    let settings = ImpactMapSettings {
        time_limit: horizon_s,
        relative_tolerance,
        ..ImpactMapSettings::default()
    };
    let mut walls = Vec::with_capacity(TIMED_REPEATS);
    let mut last = None;
    let cpu0 = thread_cpu_s();
    for _ in 0..TIMED_REPEATS {
        let clock = Instant::now();
        let r = supported_impact_map(&approach, &supports, &c.impact, friction, &settings);
        walls.push(clock.elapsed().as_secs_f64());
        last = Some(r);
    }
    let cpu_repeats_s = thread_cpu_s().zip(cpu0).map(|(b, a)| b - a);
    let map = match last? {
        Ok(m) => m,
        Err(e) => {
            eprintln!("impact-split: supported map at {t} s: {e}");
            return None;
        }
    };
    walls.sort_by(f64::total_cmp);
    let tau = map.contact.duration;
    let v_end = [
        map.contact.exit_normal_velocity,
        map.contact.exit_slip_velocity[0],
        map.contact.exit_slip_velocity[1],
    ];
    let wall_velocity_end = surface_velocity(c.body_b, t + tau, &p);
    // The wall point's velocity change in the wall's frame, plus the frame's own.
    let dv = world(v_end) - world([approach_speed, slip.norm(), 0.0])
        + (wall_velocity_end - wall_velocity);
    // The displacement relative to the wall, the penetration set to the map's, plus the
    // wall's (trapezoid over the map).
    let [_, dx, dy] = map.displacement;
    let dx_rel = world([map.contact.end_penetration - track.penetration, dx, dy]);
    let dx_frame = 0.5 * (wall_velocity + wall_velocity_end) * tau;
    let mut y_new = y.to_vec();
    for i in 0..3 {
        y_new[offset + i] += dx_rel[i] + dx_frame[i];
        y_new[offset + 7 + i] += dv[i];
    }
    Some(SupportedHybrid {
        start: (t + tau, y_new),
        normal_slip: map.normal_force_slip_integral() + frozen_normal_slip * tau,
        map,
        wall_s: walls[TIMED_REPEATS / 2],
        cpu_repeats_s,
        weight_impulse: mass * system.gravity.norm() * tau,
    })
}

/// The supported hybrid's table: against the resolved run and beside the other two hybrids.
pub(crate) fn supported_hybrid_table() -> Table {
    Table::new(
        "Impact split: the supported map's hybrid against the resolved run from the same touches",
        &[
            ("case", "case"),
            ("mode", "global integrator after the map"),
            ("restarts", "touches"),
            ("resolved_steps", "resolved: accepted steps"),
            ("supported_steps", "supported hybrid: steps"),
            ("saved", "steps resolved / supported hybrid"),
            (
                "map_slip",
                "frozen-rest map hybrid: ∫N\\|v_slip\\| dt vs resolved",
            ),
            ("body_slip", "body hybrid: ∫N\\|v_slip\\| dt vs resolved"),
            (
                "supported_slip",
                "supported hybrid: ∫N\\|v_slip\\| dt vs resolved",
            ),
            ("supported_slip_case", "supported hybrid: vs case tol"),
            (
                "supported_damping",
                "supported hybrid: damping work vs resolved",
            ),
            ("resolved_cpu", "resolved: CPU s"),
            ("body_cpu", "body hybrid: CPU s, transients included"),
            ("supported_cpu", "supported hybrid: CPU s, maps included"),
            ("map_us", "µs per supported map (median wall)"),
            ("map_cpu_us", "µs per supported map (mean CPU)"),
            ("map_steps", "map steps (accepted + rejected) per touch"),
            (
                "support_share",
                "supports' share of the map's ∫N\\|v_slip\\| dt",
            ),
            ("support_load", "supports' Σ∫N dt / (m g T)"),
            ("lifted", "supports let go"),
        ],
    )
}

/// One row of [`supported_hybrid_table`]: `[reference, resolved, map, body, supported]` in
/// the row's mode (reference: resolved at the case tolerance) and the maps.
pub(crate) fn supported_hybrid_row(
    case_name: &str,
    mode: &str,
    [reference, resolved, map, body, supported]: [GroupResult; 5],
    body_cpu_s: Option<f64>,
    hybrids: &[SupportedHybrid],
) -> Vec<Cell> {
    let diff = |a: f64, b: f64| Cell::text(format!("{:+.3} %", 100.0 * (a / b - 1.0)));
    let n = hybrids.len().max(1) as f64;
    let mut walls: Vec<f64> = hybrids.iter().map(|h| h.wall_s).collect();
    walls.sort_by(f64::total_cmp);
    let wall = walls.get(walls.len() / 2).copied();
    let cpu_per_map: Option<f64> = hybrids
        .iter()
        .map(|h| h.cpu_repeats_s.map(|s| s / TIMED_REPEATS as f64))
        .sum::<Option<f64>>()
        .map(|s| s / n);
    let steps: usize = hybrids
        .iter()
        .map(|h| h.map.contact.steps + h.map.contact.rejected_steps)
        .sum();
    let (mut support_slip, mut total, mut load, mut weight) = (0.0, 0.0, 0.0, 0.0);
    let mut lifted = 0u64;
    for h in hybrids {
        total += h.map.normal_force_slip_integral();
        weight += h.weight_impulse;
        for s in h.map.shares() {
            support_slip += s.normal_force_slip_integral;
            load += s.normal_impulse;
            lifted += u64::from(s.lifted);
        }
    }
    vec![
        Cell::text(case_name),
        Cell::text(mode),
        Cell::Int(hybrids.len() as u64),
        Cell::Int(resolved.accepted),
        Cell::Int(supported.accepted),
        Cell::Num(resolved.accepted as f64 / supported.accepted.max(1) as f64),
        diff(map.normal_slip, resolved.normal_slip),
        diff(body.normal_slip, resolved.normal_slip),
        diff(supported.normal_slip, resolved.normal_slip),
        diff(supported.normal_slip, reference.normal_slip),
        diff(supported.damping_j, resolved.damping_j),
        Cell::opt(resolved.cpu_s),
        Cell::opt(body.cpu_s.zip(body_cpu_s).map(|(a, b)| a + b)),
        Cell::opt(supported.cpu_s.zip(cpu_per_map).map(|(a, b)| a + b * n)),
        Cell::opt(wall.map(|s| s * 1e6)),
        Cell::opt(cpu_per_map.map(|s| s * 1e6)),
        Cell::Num(steps as f64 / n),
        Cell::Num(support_slip / total),
        Cell::Num(load / weight),
        Cell::Int(lifted),
    ]
}

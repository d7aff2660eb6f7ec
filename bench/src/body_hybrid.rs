//! The impact-split study's second hybrid: at a touch, the touching body's transient with all
//! its contacts (`physics::body_transient`: the floor carried with the wall, the tube on its
//! prescribed motion) over the same 20 µs as the frozen-rest map, its end state handed to the
//! global integrator. Beside the map's hybrid in `impact-split`'s restart table, and summed up
//! in its own table.

use super::*;
use railwear::physics::body::BodyKind;
use railwear::physics::body_transient::{body_transient, BodyTransient, BodyTransientSettings};
use railwear::physics::contact::TrackState;

/// One touch's transient and the start it hands over.
pub(crate) struct BodyHybrid {
    /// Time and system state at the end of the transient.
    pub(crate) start: (f64, Vec<f64>),
    /// The transient itself.
    pub(crate) transient: BodyTransient,
    /// Wall-clock time of one evaluation, s (the median of [`TIMED_REPEATS`]).
    pub(crate) wall_s: f64,
    /// This thread's CPU time over the [`TIMED_REPEATS`] evaluations, s (10 ms ticks: read
    /// as a sum over many touches).
    pub(crate) cpu_repeats_s: Option<f64>,
    /// The body's weight times the transient's duration, N·s, and gravity's unit direction.
    pub(crate) weight_impulse: f64,
    pub(crate) down: Vector3<f64>,
}

/// Evaluations of each transient for its wall-clock time.
pub(crate) const TIMED_REPEATS: usize = 5;

impl BodyHybrid {
    /// `∫N|v_slip| dt` of all the body's tracks over the transient, N·m.
    pub(crate) fn normal_slip(&self) -> f64 {
        self.transient
            .tracks
            .iter()
            .map(|t| t.normal_force_slip_integral)
            .sum()
    }
}

/// The body transient of the body carrying `track`'s pieces, from the system state `y` at
/// `t` with `settings`. None when that body is not dynamic or the transient fails (printed).
pub(crate) fn body_hybrid_start(
    model: &BuiltModel,
    t: f64,
    y: &[f64],
    track: &TrackState,
    settings: &BodyTransientSettings,
) -> Option<BodyHybrid> {
    let system = &model.system;
    let body = system.contacts[track.contact as usize].body_a;
    let BodyKind::Dynamic { offset } = system.bodies[body].kind else {
        return None;
    };
    let mut walls = Vec::with_capacity(TIMED_REPEATS);
    let mut last = None;
    let cpu0 = thread_cpu_s();
    for _ in 0..TIMED_REPEATS {
        let clock = Instant::now();
        let r = body_transient(system, body, t, y, settings);
        walls.push(clock.elapsed().as_secs_f64());
        last = Some(r);
    }
    let transient = match last? {
        Ok(r) => r,
        Err(e) => {
            eprintln!("impact-split: body transient at {t} s: {e}");
            return None;
        }
    };
    let cpu_repeats_s = thread_cpu_s().zip(cpu0).map(|(b, a)| b - a);
    walls.sort_by(f64::total_cmp);
    let mut y_end = y.to_vec();
    transient.write_end_state(&mut y_end, offset);
    Some(BodyHybrid {
        start: (t + transient.duration, y_end),
        wall_s: walls[TIMED_REPEATS / 2],
        cpu_repeats_s,
        weight_impulse: system.bodies[body].mass.mass * system.gravity.norm() * transient.duration,
        down: system
            .gravity
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::zeros),
        transient,
    })
}

/// The summary table's columns.
pub(crate) fn body_hybrid_table() -> Table {
    Table::new(
        "Impact split: the two hybrids against the resolved run from the same touches",
        &[
            ("case", "case"),
            ("mode", "global integrator after the transient"),
            ("restarts", "touches"),
            ("resolved_steps", "resolved: accepted steps"),
            ("map_steps", "map hybrid: steps"),
            ("body_steps", "body hybrid: steps"),
            ("saved", "steps resolved / body hybrid"),
            ("map_slip", "map hybrid: ∫N\\|v_slip\\| dt vs resolved"),
            ("body_slip", "body hybrid: ∫N\\|v_slip\\| dt vs resolved"),
            (
                "body_slip_case",
                "body hybrid: ∫N\\|v_slip\\| dt vs case tol",
            ),
            ("map_damping", "map hybrid: damping work vs resolved"),
            ("body_damping", "body hybrid: damping work vs resolved"),
            ("transient_us", "µs per body transient (median wall)"),
            ("transient_cpu_us", "µs per body transient (mean CPU)"),
            ("resolved_cpu", "resolved: CPU s"),
            ("body_cpu", "body hybrid: CPU s, transients included"),
            (
                "transient_steps",
                "transient steps (accepted + rejected) per touch",
            ),
            (
                "transient_residual",
                "largest \\|energy residual\\| / dissipated per transient",
            ),
            (
                "floor_share",
                "share of the transient's ∫N\\|v_slip\\| dt off the touching track",
            ),
            ("floor_load", "other tracks' Σ∫N dt / (m g T)"),
            (
                "wall_friction",
                "touching track's friction impulse along g / (other tracks' Σ∫N dt − m g T)",
            ),
        ],
    )
}

/// What one group of restarts measured in one mode: accepted steps, `∫N|v_slip| dt`, damping.
#[derive(Clone, Copy)]
pub(crate) struct GroupResult {
    pub(crate) accepted: u64,
    pub(crate) normal_slip: f64,
    pub(crate) damping_j: f64,
    /// CPU time of the group's global integration, s.
    pub(crate) cpu_s: Option<f64>,
}

/// One summary row: the resolved, the map's and the body transient's hybrid in one mode.
pub(crate) fn body_hybrid_row(
    case_name: &str,
    mode: &str,
    [reference, resolved, map, body]: [GroupResult; 4],
    hybrids: &[(&TrackState, BodyHybrid)],
) -> Vec<Cell> {
    let diff = |a: f64, b: f64| Cell::text(format!("{:+.2} %", 100.0 * (a / b - 1.0)));
    let n = hybrids.len().max(1) as f64;
    let mut walls: Vec<f64> = hybrids.iter().map(|(_, h)| h.wall_s).collect();
    walls.sort_by(f64::total_cmp);
    let wall = walls.get(walls.len() / 2).copied();
    let cpu: Option<f64> = hybrids
        .iter()
        .map(|(_, h)| h.cpu_repeats_s.map(|s| s / TIMED_REPEATS as f64))
        .sum();
    let steps: usize = hybrids
        .iter()
        .map(|(_, h)| h.transient.steps + h.transient.rejected_steps)
        .sum();
    let residual = hybrids
        .iter()
        .map(|(_, h)| (h.transient.energy_residual() / h.transient.dissipated()).abs())
        .fold(0.0f64, f64::max);
    let (mut off_track, mut total) = (0.0, 0.0);
    let (mut off_load, mut weight, mut wall_down) = (0.0, 0.0, 0.0);
    for (track, h) in hybrids {
        weight += h.weight_impulse;
        for t in &h.transient.tracks {
            total += t.normal_force_slip_integral;
            if (t.contact, t.track) != (track.contact, track.track) {
                off_track += t.normal_force_slip_integral;
                off_load += t.normal_impulse;
            } else {
                wall_down += t.tangential_impulse.dot(&h.down);
            }
        }
    }
    vec![
        Cell::text(case_name),
        Cell::text(mode),
        Cell::Int(hybrids.len() as u64),
        Cell::Int(resolved.accepted),
        Cell::Int(map.accepted),
        Cell::Int(body.accepted),
        Cell::Num(resolved.accepted as f64 / body.accepted.max(1) as f64),
        diff(map.normal_slip, resolved.normal_slip),
        diff(body.normal_slip, resolved.normal_slip),
        diff(body.normal_slip, reference.normal_slip),
        diff(map.damping_j, resolved.damping_j),
        diff(body.damping_j, resolved.damping_j),
        Cell::opt(wall.map(|s| s * 1e6)),
        Cell::opt(cpu.map(|s| s * 1e6 / n)),
        Cell::opt(resolved.cpu_s),
        Cell::opt(body.cpu_s.zip(cpu).map(|(a, b)| a + b)),
        Cell::Num(steps as f64 / n),
        Cell::Num(residual),
        Cell::Num(off_track / total),
        Cell::Num(off_load / weight),
        Cell::Num(wall_down / (off_load - weight)),
    ]
}

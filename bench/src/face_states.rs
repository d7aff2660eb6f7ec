//! `face-states`: issue 27's per-state face study. One case (launcher-loose by default) runs
//! with the lattice at `record_points` points per edge; states along its excitation window are
//! recorded, and at each the contacts are evaluated with the exact face contact and with the
//! lattice at several points per edge (same state, same time, so the same rail motion), and
//! with the exact contact's friction taken per part at its load centre
//! (`FrictionRule::PerPart`, issue 27's cheaper friction) against the per-node law: each
//! contact's normal force, force and torque on its body a, and friction power, and each
//! track's normal force. The question is whether the lattice converges to the exact contact
//! at the states the dynamics visits, and which track makes a difference.

use super::*;
use railwear::models::run::record_states;
use railwear::physics::contact::{FaceContact, FrictionRule, TrackState};
use railwear::physics::system::MultibodySystem;

/// What `face-states` runs.
pub(crate) struct FaceStatesBench {
    pub(crate) case: String,
    pub(crate) record_points: usize,
    pub(crate) ladder: Vec<usize>,
    pub(crate) settle: f64,
    pub(crate) window: f64,
    pub(crate) every: f64,
}

/// Per contact: (normal force N, |force| N, torque about body a's centre N·m (vector),
/// friction power W), and per (contact, track) the normal force.
struct Evaluation {
    contacts: Vec<(f64, Vector3<f64>, Vector3<f64>, f64)>,
    tracks: Vec<TrackState>,
}

fn evaluate_all(sys: &MultibodySystem, t: f64, y: &[f64]) -> Evaluation {
    let mut ws = sys.workspace();
    let mut tracks = Vec::new();
    sys.tracks(t, y, &mut ws, &mut |tr| tracks.push(*tr));
    let frames = ws.frames.clone();
    let mut contacts = Vec::new();
    for (ci, c) in sys.contacts.iter().enumerate() {
        let mut wrenches = vec![(Vector3::zeros(), Vector3::zeros()); frames.len()];
        let mut n = 0.0;
        let mut fp = 0.0;
        c.evaluate(ci as u32, &frames, Some(&mut wrenches), &mut |tr| {
            n += tr.normal_force;
            fp += tr.friction_power;
        });
        contacts.push((n, wrenches[c.body_a].0, wrenches[c.body_a].1, fp));
    }
    Evaluation { contacts, tracks }
}

/// Adds, per contact, `eval`'s normal force and friction power and its force and torque gaps
/// `|ΔF|`, `|Δτ|` against `exact` at the same state to `sums`.
fn add_gaps(sums: &mut [(f64, f64, f64, f64)], eval: &Evaluation, exact: &Evaluation) {
    for ((sum, c), e) in sums.iter_mut().zip(&eval.contacts).zip(&exact.contacts) {
        sum.0 += c.0;
        sum.1 += c.3;
        sum.2 += (c.1 - e.1).norm();
        sum.3 += (c.2 - e.2).norm();
    }
}

pub(crate) fn face_states(configs_dir: &Path, b: &FaceStatesBench) -> Result<Vec<Table>> {
    let mut case = load_case(&configs_dir.join(format!("{}.toml", b.case)))?;
    case.simulation.settle_s = b.settle;
    case.simulation.duration_s = b.window;
    let model_at = |n: Option<usize>| -> Result<BuiltModel> {
        let mut case = case.clone();
        match n {
            Some(n) => {
                // The case's validation caps the points at 33: finer lattices are set on the
                // built contacts.
                case.simulation.contact_points_per_edge = n.min(33);
                case.simulation.face_contact = Some(FaceContact::Lattice);
            }
            None => case.simulation.face_contact = Some(FaceContact::Exact),
        }
        let mut model = build(&case, configs_dir)?;
        if let Some(n) = n.filter(|&n| n > 33) {
            for c in &mut model.system.contacts {
                *c = c.clone().with_points_per_edge(n);
            }
        }
        Ok(model)
    };
    let recorder = model_at(Some(b.record_points))?;
    let options = run_options(&case)?;
    let states = record_states(&recorder, &options, &RunControl::silent(), b.every)
        .map_err(|e| anyhow!("{}: {e}", b.case))?;
    eprintln!("face-states: {} states recorded", states.len());
    let exact = model_at(None)?;
    // The exact contact with friction per part at its load centre (issue 27's cheaper friction,
    // measured against the per-node law at the same states).
    let mut per_part = model_at(None)?;
    for c in &mut per_part.system.contacts {
        *c = c.clone().with_friction_rule(FrictionRule::PerPart);
    }
    let lattices: Vec<(usize, BuiltModel)> = b
        .ladder
        .iter()
        .map(|&n| Ok((n, model_at(Some(n))?)))
        .collect::<Result<_>>()?;
    let names: Vec<String> = exact
        .system
        .contacts
        .iter()
        .map(|c| c.name.clone())
        .collect();
    // Sums over states, per contact: exact (N, friction power), and per lattice (N, friction
    // power, Σ|ΔF|, Σ|Δτ|) against exact, and Σ|F_exact|, Σ|τ_exact|.
    let nc = names.len();
    let mut ex = vec![(0.0, 0.0, 0.0, 0.0); nc];
    let mut lat = vec![vec![(0.0, 0.0, 0.0, 0.0); nc]; lattices.len()];
    // Friction per part: (N, friction power, Σ|ΔF|, Σ|Δτ|) against exact, and Σ|ΔP_friction|.
    let mut part = vec![(0.0, 0.0, 0.0, 0.0); nc];
    let mut part_power_gap = vec![0.0; nc];
    // Per (contact, track): Σ N exact and per lattice.
    let mut per_track: Vec<((u32, u32), f64, Vec<f64>)> = Vec::new();
    for (si, (t, y)) in states.iter().enumerate() {
        let e = evaluate_all(&exact.system, *t, y);
        for (ci, c) in e.contacts.iter().enumerate() {
            ex[ci].0 += c.0;
            ex[ci].1 += c.3;
            ex[ci].2 += c.1.norm();
            ex[ci].3 += c.2.norm();
        }
        let mut add_track = |tr: &TrackState, slot: Option<usize>| {
            let key = (tr.contact, tr.track);
            let i = match per_track.iter().position(|p| p.0 == key) {
                Some(i) => i,
                None => {
                    per_track.push((key, 0.0, vec![0.0; lattices.len()]));
                    per_track.len() - 1
                }
            };
            match slot {
                None => per_track[i].1 += tr.normal_force,
                Some(l) => per_track[i].2[l] += tr.normal_force,
            }
        };
        for tr in &e.tracks {
            add_track(tr, None);
        }
        let pp = evaluate_all(&per_part.system, *t, y);
        add_gaps(&mut part, &pp, &e);
        for (ci, c) in pp.contacts.iter().enumerate() {
            part_power_gap[ci] += (c.3 - e.contacts[ci].3).abs();
        }
        let mut line = format!("t {t:.4} exact N");
        for c in &e.contacts {
            line += &format!(" {:.2}", c.0);
        }
        for (li, (n, m)) in lattices.iter().enumerate() {
            let l = evaluate_all(&m.system, *t, y);
            line += &format!(" | {n}:");
            add_gaps(&mut lat[li], &l, &e);
            for c in &l.contacts {
                line += &format!(" {:.2}", c.0);
            }
            for tr in &l.tracks {
                add_track(tr, Some(li));
            }
        }
        if si % 10 == 0 {
            eprintln!("{line}");
        }
    }
    let mut table = Table::new(
        format!(
            "Per-state face study: {} recorded with the lattice at {} points, {} states every {} s; sums over states, lattice vs exact",
            b.case,
            b.record_points,
            states.len(),
            b.every
        ),
        &[
            ("contact", "contact"),
            ("variant", "face contact"),
            ("normal", "mean normal force (N)"),
            ("normal_vs_exact", "Δ mean N vs exact"),
            ("friction", "mean friction power (W)"),
            ("friction_vs_exact", "Δ friction power vs exact"),
            ("force_gap", "Σ|ΔF| / Σ|F_exact|"),
            ("torque_gap", "Σ|Δτ| / Σ|τ_exact|"),
        ],
    );
    let count = states.len().max(1) as f64;
    let pct =
        |a: f64, r: f64| Cell::text(format!("{:+.3} %", 100.0 * (a - r) / r.abs().max(1e-300)));
    // One variant's row of contact `ci` from its sums against exact ([`add_gaps`]).
    let gap_row = |ci: usize, label: String, g: (f64, f64, f64, f64)| {
        vec![
            Cell::text(&names[ci]),
            Cell::text(label),
            Cell::Num(g.0 / count),
            pct(g.0, ex[ci].0),
            Cell::Num(g.1 / count),
            pct(g.1, ex[ci].1),
            Cell::Num(g.2 / ex[ci].2.max(1e-300)),
            Cell::Num(g.3 / ex[ci].3.max(1e-300)),
        ]
    };
    for ci in 0..nc {
        table.row(vec![
            Cell::text(&names[ci]),
            Cell::text("exact"),
            Cell::Num(ex[ci].0 / count),
            Cell::text("-"),
            Cell::Num(ex[ci].1 / count),
            Cell::text("-"),
            Cell::text("-"),
            Cell::text("-"),
        ]);
        table.row(gap_row(ci, "exact, friction per part".into(), part[ci]));
        table.note(format!(
            "{}: friction per part, Σ|ΔP_friction| / ΣP_friction over the states = {:.3e}",
            names[ci],
            part_power_gap[ci] / ex[ci].1.abs().max(1e-300)
        ));
        for (li, (n, _)) in lattices.iter().enumerate() {
            table.row(gap_row(ci, format!("lattice {n}"), lat[li][ci]));
        }
    }
    let mut tracks = Table::new(
        "Per-state face study: mean normal force per track (contact, piece × faces + face)",
        &[
            ("contact", "contact"),
            ("track", "track"),
            ("exact", "exact (N)"),
            ("lattice", "lattice (points: N, Δ vs exact)"),
        ],
    );
    per_track.sort_by_key(|p| p.0);
    for ((c, t), e, l) in &per_track {
        let cells: Vec<String> = lattices
            .iter()
            .zip(l)
            .map(|((n, _), v)| {
                format!(
                    "{n}: {:.4} ({:+.2} %)",
                    v / count,
                    100.0 * (v - e) / e.abs().max(1e-300)
                )
            })
            .collect();
        tracks.row(vec![
            Cell::text(&names[*c as usize]),
            Cell::Int(u64::from(*t)),
            Cell::Num(e / count),
            Cell::text(cells.join(", ")),
        ]);
    }
    Ok(vec![table, tracks])
}

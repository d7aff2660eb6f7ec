//! `impact-map`: CPU cost of one contact-local impulse map (issue 28, first part) on the
//! thesis' 46 g cube: the median over batches of repeated evaluations, with its steps.

use super::*;
use railwear::physics::friction::FrictionParams;
use railwear::physics::impact_map::{impact_map, ContactApproach, ImpactMapSettings};

pub(crate) fn impact_map_cost(batches: usize, per_batch: usize) -> Result<Vec<Table>> {
    if batches == 0 || per_batch == 0 {
        bail!("--batches and --per-batch must be >= 1");
    }
    let mass = 0.046;
    let thesis = ImpactParams::thesis_table_5_2();
    let friction = FrictionParams::thesis_table_5_2();
    let head_on = |speed: f64| ContactApproach::head_on(mass, speed);
    let sliding = ContactApproach {
        slip_velocity: [0.2, 0.05],
        external_normal_force: mass * 9.81,
        ..head_on(0.1)
    };
    let cases = [
        (
            "undamped (c_max 0, e 2), 0.5 m/s, to separation",
            head_on(0.5),
            ImpactParams {
                max_damping: 0.0,
                ..thesis
            },
            1.0,
        ),
        (
            "c_max 20 N·s/m, 0.1 m/s, 2-D slip, gravity, to separation",
            sliding,
            ImpactParams {
                max_damping: 20.0,
                ..thesis
            },
            1.0,
        ),
        (
            "thesis Table 5.2, 0.1 m/s, 2-D slip, gravity, 1e-4 s horizon",
            sliding,
            thesis,
            1e-4,
        ),
        (
            "thesis Table 5.2, 0.1 m/s, 2-D slip, gravity, 1e-3 s horizon",
            sliding,
            thesis,
            1e-3,
        ),
    ];
    let mut t = Table::new(
        "Contact-local impulse map: CPU cost of one evaluation (46 g cube)",
        &[
            ("case", "case"),
            ("relative_tolerance", "relative tolerance"),
            ("end", "end"),
            ("steps", "accepted steps"),
            ("rejected", "rejected"),
            ("us_per_map", "µs per map (median)"),
            ("us_per_step", "µs per step"),
        ],
    );
    for ((name, approach, impact, time_limit), relative_tolerance) in cases
        .into_iter()
        .flat_map(|case| [(case, 1e-10), (case, 1e-7)])
    {
        let settings = ImpactMapSettings {
            time_limit,
            relative_tolerance,
            ..ImpactMapSettings::default()
        };
        let map = impact_map(&approach, &impact, &friction, &settings)?;
        let mut per_map = Vec::with_capacity(batches);
        for _ in 0..batches {
            let start = Instant::now();
            for _ in 0..per_batch {
                std::hint::black_box(impact_map(
                    std::hint::black_box(&approach),
                    &impact,
                    &friction,
                    &settings,
                )?);
            }
            per_map.push(start.elapsed().as_secs_f64() * 1e6 / per_batch as f64);
        }
        per_map.sort_by(f64::total_cmp);
        let median = per_map[per_map.len() / 2];
        t.row(vec![
            Cell::text(name),
            Cell::Num(relative_tolerance),
            Cell::text(format!("{:?}", map.end)),
            Cell::Int(map.steps as u64),
            Cell::Int(map.rejected_steps as u64),
            Cell::Num(median),
            Cell::Num(median / (map.steps + map.rejected_steps) as f64),
        ]);
    }
    t.note(format!(
        "median over {batches} batches of {per_batch} evaluations, release build, one thread"
    ));
    t.note(machine_note());
    Ok(vec![t])
}

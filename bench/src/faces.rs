//! `convergence --faces`: issue 27's face study. For each case, the contact-point lattice at
//! several points per edge and the exact face contact (with `--friction-per-part` also with
//! friction per part, `FrictionRule::PerPart`), each at the case tolerance: friction power
//! and every contact's wear rate, the lattice's last three runs extrapolated to zero spacing
//! as the reference, and the CPU cost per accepted step.

use super::convergence::{run_variant, Measured, QuantityKind, Variant};
use super::*;
use railwear::physics::contact::{FaceContact, FrictionRule};

/// `Q(h) = Q∞ + C h^p` through three (spacing, value) pairs with `h1 > h2 > h3`: `(Q∞, p)`,
/// `p` found by bisection in [0.25, 6]; None when the three are not monotone in `h` (then no
/// power law fits).
pub(crate) fn extrapolate(pairs: [(f64, f64); 3]) -> Option<(f64, f64)> {
    let [(h1, q1), (h2, q2), (h3, q3)] = pairs;
    let (d12, d23) = (q1 - q2, q2 - q3);
    if d23 == 0.0 {
        return Some((q3, f64::NAN));
    }
    let target = d12 / d23;
    if target.is_nan() || target <= 0.0 {
        return None;
    }
    let ratio = |p: f64| (h1.powf(p) - h2.powf(p)) / (h2.powf(p) - h3.powf(p));
    let (mut lo, mut hi) = (0.25, 6.0);
    // ratio(p) increases with p.
    if target < ratio(lo) || target > ratio(hi) {
        return None;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let p = 0.5 * (lo + hi);
    let c = d23 / (h2.powf(p) - h3.powf(p));
    Some((q3 - c * h3.powf(p), p))
}

pub(crate) fn faces(configs_dir: &Path, b: &ConvergenceBench) -> Result<Vec<Table>> {
    let ladder = &b.faces;
    if ladder.iter().any(|&n| n < 2) {
        bail!("--faces lists lattice points per edge >= 2, e.g. 5,9,13,17");
    }
    let mut runs = Table::new(
        "Face study: runs at the case tolerance (no track recording)",
        &[
            ("case", "case"),
            ("variant", "face contact"),
            ("accepted", "accepted steps"),
            ("cpu_s", "CPU s"),
            ("cpu_us_per_step", "CPU µs per accepted step"),
            ("real_time_factor_cpu", "real-time factor (CPU)"),
            ("energy_residual", "energy residual / dissipated"),
        ],
    );
    let mut quantities = Table::new(
        "Face study: friction power and wear rates, lattice ladder, its extrapolation and the exact face contact",
        &[
            ("case", "case"),
            ("quantity", "quantity"),
            ("lattice", "lattice values (points per edge: value)"),
            ("reference", "lattice extrapolated (last three)"),
            ("order", "fitted order p"),
            ("exact", "exact face contact"),
            ("exact_vs_ref", "Δ exact vs reference"),
            ("first_vs_ref", "Δ first lattice vs reference"),
            ("exact_vs_9", "Δ exact vs 9 points"),
            ("per_part_vs_exact", "Δ exact with friction per part vs exact"),
        ],
    );
    for case_name in b.case_names() {
        let settle = b.settle(case_name);
        let mut measured: Vec<(String, Measured)> = Vec::new();
        for &n in ladder {
            let mut v = Variant::plain(format!("lattice {n}"));
            v.points_per_edge = Some(n);
            v.face_contact = Some(FaceContact::Lattice);
            eprintln!("faces: {case_name} {} ...", v.label);
            measured.push((
                v.label.clone(),
                run_variant(configs_dir, case_name, settle, b.window, &v)?,
            ));
        }
        let mut v = Variant::plain("exact".into());
        v.face_contact = Some(FaceContact::Exact);
        eprintln!("faces: {case_name} exact ...");
        measured.push((
            "exact".into(),
            run_variant(configs_dir, case_name, settle, b.window, &v)?,
        ));
        if b.friction_per_part {
            v.label = "exact, friction per part".into();
            v.friction_rule = FrictionRule::PerPart;
            eprintln!("faces: {case_name} {} ...", v.label);
            measured.push((
                v.label.clone(),
                run_variant(configs_dir, case_name, settle, b.window, &v)?,
            ));
        }
        for (label, m) in &measured {
            runs.row(vec![
                Cell::text(case_name),
                Cell::text(label.as_str()),
                Cell::Int(m.accepted),
                Cell::opt(m.cpu_s),
                Cell::opt(m.cpu_s.map(|c| 1e6 * c / m.accepted.max(1) as f64)),
                Cell::opt(m.cpu_s.map(|c| m.simulated_s / c.max(1e-9))),
                Cell::opt(m.energy_residual_rel),
            ]);
        }
        let (lattice, exact) = measured.split_at(ladder.len());
        let per_part = exact.get(1).map(|m| &m.1);
        let exact = &exact[0].1;
        let spacing = |n: usize| 1.0 / (n as f64 - 1.0);
        for (i, (name, _, kind)) in exact.quantities.iter().enumerate() {
            if *kind != QuantityKind::Relative || name.starts_with("response") {
                continue;
            }
            let val = |m: &Measured| m.quantities.get(i).map_or(f64::NAN, |q| q.1);
            let rel = |a: f64, r: f64| (a - r) / r.abs().max(f64::MIN_POSITIVE);
            let pct = |x: Option<f64>| {
                Cell::text(
                    x.filter(|x| x.is_finite())
                        .map_or("-".into(), |x| format!("{:+.2} %", 100.0 * x)),
                )
            };
            let values: Vec<String> = ladder
                .iter()
                .zip(lattice)
                .map(|(n, (_, m))| format!("{n}: {}", fmt_num(val(m))))
                .collect();
            let fit = (ladder.len() >= 3).then(|| {
                let k = ladder.len();
                let pair = |j: usize| (spacing(ladder[j]), val(&lattice[j].1));
                extrapolate([pair(k - 3), pair(k - 2), pair(k - 1)])
            });
            let reference = fit.flatten().map(|f| f.0);
            let at9 = ladder
                .iter()
                .position(|&n| n == 9)
                .map(|j| val(&lattice[j].1));
            quantities.row(vec![
                Cell::text(case_name),
                Cell::text(name),
                Cell::text(values.join(", ")),
                Cell::opt(reference),
                Cell::opt(fit.flatten().map(|f| f.1)),
                Cell::Num(val(exact)),
                pct(reference.map(|r| rel(val(exact), r))),
                pct(reference.map(|r| rel(val(&lattice[0].1), r))),
                pct(at9.map(|r| rel(val(exact), r))),
                pct(per_part.map(|m| rel(val(m), val(exact)))),
            ]);
        }
    }
    runs.note(format!(
        "settle {} s (rattle box) / {} s (launcher), window {} s, full error control at the case tolerance; \
         CPU s = this thread's user + system time (10 ms ticks)",
        b.settle_box, b.settle_launcher, b.window
    ));
    runs.note(machine_note());
    quantities.note(
        "reference: Q(h) = Q∞ + C h^p through the last three lattice runs (h = 1/(n − 1)); \
         '-' where they are not monotone in h",
    );
    Ok(vec![runs, quantities])
}

/// `reduced`: issue 53's comparison. For each case the exact face contact and the reduced face
/// law (`face_contact = "reduced"`), each at the case tolerance without track recording: CPU
/// cost, the reduced law's census (parts in closed form, largest friction estimate), and the
/// friction power and every contact's wear rate of the reduced law against the exact one.
pub(crate) fn reduced(
    configs_dir: &Path,
    cases: &str,
    settle: f64,
    window: f64,
    tolerances: &[f64],
) -> Result<Vec<Table>> {
    let mut runs = Table::new(
        "Reduced face law against the exact face contact: runs at the case tolerance (no track recording)",
        &[
            ("case", "case"),
            ("variant", "face contact"),
            ("accepted", "accepted steps"),
            ("cpu_s", "CPU s"),
            ("cpu_us_per_step", "CPU µs per accepted step"),
            ("real_time_factor_cpu", "real-time factor (CPU)"),
            ("energy_residual", "energy residual / dissipated"),
            ("closed_share", "parts taken per part"),
            ("over_tolerance", "parts over the tolerance"),
            ("largest_estimate", "largest friction estimate used"),
        ],
    );
    let mut quantities = Table::new(
        "Reduced face law against the exact face contact: friction power and wear rates",
        &[
            ("case", "case"),
            ("quantity", "quantity"),
            ("exact", "exact"),
            ("reduced", "reduced"),
            ("difference", "Δ reduced vs exact"),
        ],
    );
    for case_name in cases.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let mut measured = Vec::new();
        let mut variants = vec![("exact".to_string(), FaceContact::Exact, None)];
        for &tol in tolerances {
            variants.push((
                format!("reduced, tolerance {tol}"),
                FaceContact::Reduced,
                Some(tol),
            ));
        }
        if tolerances.is_empty() {
            variants.push(("reduced".into(), FaceContact::Reduced, None));
        }
        for (label, law, tol) in variants {
            let mut v = Variant::plain(label.clone());
            v.face_contact = Some(law);
            v.reduced_tolerance = tol;
            eprintln!("reduced: {case_name} {label} ...");
            let m = run_variant(configs_dir, case_name, settle, window, &v)?;
            runs.row(vec![
                Cell::text(case_name),
                Cell::text(&label),
                Cell::Int(m.accepted),
                Cell::opt(m.cpu_s),
                Cell::opt(m.cpu_s.map(|c| 1e6 * c / m.accepted.max(1) as f64)),
                Cell::opt(m.cpu_s.map(|c| m.simulated_s / c.max(1e-9))),
                Cell::opt(m.energy_residual_rel),
                Cell::opt(m.reduced.map(|r| r.closed_share())),
                Cell::opt(m.reduced.map(|r| {
                    r.over_tolerance_parts as f64
                        / (r.closed_parts + r.per_node_parts).max(1) as f64
                })),
                Cell::opt(m.reduced.map(|r| r.largest_estimate)),
            ]);
            measured.push((label, m));
        }
        let exact = &measured[0].1;
        for (label, red) in &measured[1..] {
            for (i, (name, value, kind)) in exact.quantities.iter().enumerate() {
                if *kind != QuantityKind::Relative || name.starts_with("response") {
                    continue;
                }
                let other = red.quantities.get(i).map_or(f64::NAN, |q| q.1);
                quantities.row(vec![
                    Cell::text(format!("{case_name} ({label})")),
                    Cell::text(name),
                    Cell::Num(*value),
                    Cell::Num(other),
                    Cell::text(format!(
                        "{:+.3} %",
                        100.0 * (other - value) / value.abs().max(f64::MIN_POSITIVE)
                    )),
                ]);
            }
        }
    }
    runs.note(format!(
        "settle {settle} s, window {window} s, full error control at the case tolerance; \
         CPU s = this thread's user + system time (10 ms ticks)"
    ));
    runs.note(machine_note());
    Ok(vec![runs, quantities])
}

//! Command-line front ends of the library: `railwear run` and `railwear validate`.
//! (anyhow is allowed here: this is the binary edge.)

use crate::models::case::{load_case, run_case};
use crate::pipeline::{Progress, RunControl};
use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// `railwear run <config>`.
pub fn run(
    config_file: &Path,
    out: Option<&Path>,
    duration: Option<f64>,
    settle: Option<f64>,
    configs_dir: &Path,
) -> Result<()> {
    let mut case = load_case(config_file)?;
    if let Some(d) = duration {
        case.simulation.duration_s = d;
    }
    if let Some(s) = settle {
        case.simulation.settle_s = s;
    }
    case.validate()
        .map_err(|e| anyhow::anyhow!("{}: {}", e.field, e.rule))?;
    let end = case.simulation.settle_s + case.simulation.duration_s;
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {percent}% sim {prefix} eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(case.name.clone());
    let b2 = bar.clone();
    let control = RunControl {
        cancel: Arc::new(AtomicBool::new(false)),
        progress: Arc::new(move |p: Progress| {
            b2.set_position((p.fraction * 1000.0) as u64);
            b2.set_prefix(format!("{:.3}/{:.3} s", p.simulated_time_s, p.end_time_s));
        }),
    };
    let (report, outcome) = run_case(&case, configs_dir, &control)?;
    bar.finish_and_clear();
    let dir = out
        .map(Path::to_path_buf)
        .unwrap_or_else(|| Path::new("out").join(&case.name));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    std::fs::write(
        dir.join("summary.json"),
        serde_json::to_string_pretty(&outcome.summary)?,
    )?;
    let mut csv = std::io::BufWriter::new(std::fs::File::create(dir.join("tracks.csv"))?);
    writeln!(csv, "{}", crate::physics::track::TrackSample::CSV_HEADER)?;
    for s in &outcome.tracks {
        writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.time_s,
            s.contact,
            s.track,
            s.normal_force_n,
            s.slip_velocity_m_s[0],
            s.slip_velocity_m_s[1],
            s.slip_velocity_m_s[2],
            s.slip_speed_m_s,
            s.penetration_m,
            s.penetration_rate_m_s,
            s.area_m2,
            s.pressure_pa,
            s.point_in_a_m[0],
            s.point_in_a_m[1],
            s.point_in_a_m[2],
            s.point_in_b_m[0],
            s.point_in_b_m[1],
            s.point_in_b_m[2]
        )?;
    }
    csv.flush()?;
    for (name, svg) in &outcome.plots {
        std::fs::write(dir.join(name), svg)?;
    }
    println!(
        "{}: {:.3} s simulated ({:.3} s excited) in {:.2} s wall, real-time factor {:.3}",
        case.name,
        end,
        report.window_s,
        report.wall_s,
        end / report.wall_s.max(1e-9)
    );
    println!(
        "mean normal force {:.4} N, mean friction power {:.5} W",
        report.mean_normal_force_n, report.mean_friction_power_w
    );
    println!(
        "{:<18} {:>12} {:>12} {:>12} {:>12} {:>10}",
        "contact", "wear mg/h", "a mg/h", "b mg/h", "N·v W", ">cutoff"
    );
    for c in &report.contacts {
        println!(
            "{:<18} {:>12.5} {:>12.5} {:>12.5} {:>12.5} {:>9.1}%",
            c.name,
            c.mass_rate_mg_per_h,
            c.mass_rate_a_mg_per_h,
            c.mass_rate_b_mg_per_h,
            c.mean_friction_power_w,
            100.0 * c.work_share_above_cutoff
        );
    }
    println!("{:<18} {:>12}", "body", "wear mg/h");
    for b in &report.bodies {
        println!("{:<18} {:>12.5}", b.name, b.mass_rate_mg_per_h);
    }
    println!("results in {}", dir.display());
    Ok(())
}

/// `railwear validate`: returns whether every anchor passed.
pub fn validate(json: bool, slow: bool, configs_dir: &Path) -> Result<bool> {
    let anchors = crate::validation::run_all(slow, configs_dir);
    let mut all = true;
    if json {
        for a in &anchors {
            println!("{}", serde_json::to_string(a)?);
        }
    } else {
        println!(
            "{:<72} {:>14} {:>14} {:>12} {:>10} {:>7}",
            "anchor", "expected", "measured", "tolerance", "unit", "verdict"
        );
    }
    for a in &anchors {
        all &= a.pass;
        if !json {
            println!(
                "{:<72} {:>14} {:>14} {:>12} {:>10} {:>7}",
                a.name,
                num(a.expected),
                num(a.measured),
                num(a.tolerance),
                a.unit,
                if a.pass { "PASS" } else { "FAIL" }
            );
        }
    }
    Ok(all)
}

fn num(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e6) {
        format!("{x:.4e}")
    } else {
        format!("{x:.6}")
    }
}

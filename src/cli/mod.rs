//! Command-line front ends of the library: `railwear run`, `validate`, `campaign check`,
//! `rig`, `effects`, `diagnose`, `plan-test`, and `contact-fit` ([`contact_fit`]).
//! (anyhow is allowed here: this is the binary edge.)

mod bench;
mod case_file;
pub mod contact_fit;
mod plan_test;

pub use plan_test::{plan_test, PlanTestArgs};

pub use bench::{diagnose_bench, rescore_bench};
use case_file::checked_case;

use crate::models::case::load_case;
use crate::pipeline::{run_case, Progress, RunControl};
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
    let case = checked_case(config_file, duration, settle, configs_dir)?;
    let end = case.simulation.settle_s + case.simulation.duration_s;
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {percent}% sim {prefix} eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(case.name.clone());
    let b2 = bar.clone();
    let control = RunControl::new(
        Arc::new(AtomicBool::new(false)),
        Arc::new(move |p: Progress| {
            b2.set_position((p.fraction * 1000.0) as u64);
            b2.set_prefix(format!("{:.3}/{:.3} s", p.simulated_time_s, p.end_time_s));
        }),
    );
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
    crate::physics::track::TrackSample::write_csv(&outcome.tracks, &mut csv)?;
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
    let w = report.rate_window;
    println!(
        "rates and means over {:.3} s from t = {:.3} s ({})",
        w.length_s,
        w.start_s,
        if w.after_ramp {
            "after the excitation's ramp-in"
        } else {
            "ramp-in included: the run ends before its ramp does"
        }
    );
    println!(
        "mean normal force {:.4} N, mean friction power {:.5} W (dissipated), mean N·|v_slip| {:.5} W (what the wear law integrates)",
        report.mean_normal_force_n, report.mean_friction_power_w, report.mean_normal_slip_power_w
    );
    println!(
        "{:<18} {:>12} {:>12} {:>12} {:>12} {:>10}",
        "contact", "wear mg/h", "a mg/h", "b mg/h", "N·|v| W", ">cutoff"
    );
    for c in &report.contacts {
        println!(
            "{:<18} {:>12.5} {:>12.5} {:>12.5} {:>12.5} {:>9.1}%",
            c.name,
            c.mass_rate_mg_per_h,
            c.mass_rate_a_mg_per_h,
            c.mass_rate_b_mg_per_h,
            c.mean_normal_slip_power_w,
            100.0 * c.work_share_above_cutoff
        );
    }
    println!("{:<18} {:>12}", "body", "wear mg/h");
    for b in &report.bodies {
        println!("{:<18} {:>12.5}", b.name, b.mass_rate_mg_per_h);
    }
    if let Some(e) = &report.energy {
        println!(
            "energy: drive {:.4e} J, dissipated {:.4e} J, E {:.4e} -> {:.4e} J, residual {:.2e} J ({:.2e} of the throughput){}",
            e.drive_work_j,
            e.dissipated_j,
            e.initial_energy_j,
            e.final_energy_j,
            e.residual_j,
            e.residual_relative,
            if e.balanced {
                ""
            } else {
                "  WARNING: the energy account does not close; results are suspect"
            }
        );
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

/// Thesis Table 5.3 measured rattle-box wear rates, mg/h (mean; repeats where given).
const TABLE_5_3: [(&str, f64, &str); 4] = [
    ("A", 21.13, ""),
    ("B", 97.20, ""),
    ("C", 2.03, "1.53, 2.23, 2.33"),
    ("D", 0.433, "0.267, 0.167, 0.867"),
];

/// `railwear compare-rattle-box`: runs cases A-D and writes the comparison page.
pub fn compare_rattle_box(
    duration: f64,
    settle: f64,
    out: &Path,
    configs_dir: &Path,
) -> Result<()> {
    use crate::validation::slow::TABLE_5_4_ADAMS_MG_PER_H;
    use crate::wear::law::WearLaw;
    let mut rows = Vec::new();
    for (i, (letter, adams)) in TABLE_5_4_ADAMS_MG_PER_H.iter().enumerate() {
        let path = configs_dir.join(format!("rattle-box-{letter}.toml"));
        let mut case = load_case(&path)?;
        case.simulation.duration_s = duration;
        case.simulation.settle_s = settle;
        case.simulation.record_interval_s = duration;
        eprintln!(
            "running {} ({duration} s after {settle} s settle)...",
            case.name
        );
        let (r, _) = run_case(&case, configs_dir, &RunControl::silent())?;
        let c = r
            .contacts
            .first()
            .ok_or_else(|| anyhow::anyhow!("case {} has no contact", case.name))?;
        let k_rs = case
            .rattle_box
            .as_ref()
            .and_then(|s| s.rattle_space().ok())
            .unwrap_or(f64::NAN);
        rows.push((
            TABLE_5_3[i],
            *adams,
            k_rs,
            c.clone(),
            r.wall_s,
            settle + duration,
            r.energy.as_ref().map_or(f64::NAN, |a| {
                a.residual_j / a.dissipated_j.max(f64::MIN_POSITIVE)
            }),
        ));
    }
    // The effective wear coefficient ADAMS' rate would need at railwear's friction power, and
    // the largest K(sigma) Table 4.3 allows (at the cutoff).
    let k_max = WearLaw::table_4_3()
        .coefficient_m2_per_n(WearLaw::table_4_3().cutoff_pressure_pa() * (1.0 - 1e-9))
        .unwrap_or(f64::NAN);
    let mut md = String::new();
    md.push_str(&format!(
        "Generated by `railwear compare-rattle-box --duration {duration} --settle {settle}` (code version {}). Do not edit this section by hand: the command rewrites it and keeps the rest of the file.\n\n",
        crate::models::case::code_version()
    ));
    md.push_str("Contact: Table 5.2 IMPACT and friction; wear law: Table 4.3 modified Archard in SI (sigma in Pa, K in m²/N), cutoff 2 Sy = 870 MPa; excitation 15 g at 20 Hz transverse. Wear rate = whole cube-tube contact volume × 2810 kg/m³ (the cube's share by inverse hardness is half of it: both bodies are 7075).\n\n");
    md.push_str("| case | k_rs | railwear mg/h | cube share mg/h | ADAMS Table 5.4 mg/h | measured Table 5.3 mg/h | railwear / ADAMS | work above cutoff | mean N·v W | mean N N | peak N N | K needed for ADAMS (m²/N) | energy residual / dissipated | wall s |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for ((letter, measured, repeats), adams, k_rs, c, wall, _sim, residual) in &rows {
        let density = crate::wear::material::Material::aluminium_7075_t73().density_kg_per_m3;
        let vol_rate_m3_s = adams * 1e-6 / density / 3600.0;
        let k_needed = vol_rate_m3_s / c.mean_normal_slip_power_w.max(1e-30);
        let meas = if repeats.is_empty() {
            format!("{measured}")
        } else {
            format!("{measured} ({repeats})")
        };
        md.push_str(&format!(
            "| {letter} | {k_rs:.2} | {:.4} | {:.4} | {adams} | {meas} | {:.3} | {:.1} % | {:.4} | {:.3} | {:.0} | {:.2e} | {residual:.1e} | {wall:.1} |\n",
            c.mass_rate_mg_per_h,
            c.mass_rate_a_mg_per_h,
            c.mass_rate_mg_per_h / adams,
            100.0 * c.work_share_above_cutoff,
            c.mean_normal_slip_power_w,
            c.mean_normal_force_n,
            c.peak_normal_force_n,
            k_needed,
        ));
    }
    // What the closing paragraph says is read off the rows, so the generated text cannot
    // contradict its own table: the measured rates' orders of magnitude above railwear's and
    // the share of the friction work done above the cutoff, lowest and highest over the cases.
    fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
        values
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    }
    let (above_lo, above_hi) = range(
        rows.iter()
            .map(|((_, measured, _), _, _, c, ..)| (measured / c.mass_rate_mg_per_h).log10()),
    );
    let (cut_lo, cut_hi) = range(
        rows.iter()
            .map(|(_, _, _, c, ..)| 100.0 * c.work_share_above_cutoff),
    );
    let span = |lo: f64, hi: f64| {
        let (lo, hi) = (format!("{lo:.1}"), format!("{hi:.1}"));
        if lo == hi {
            lo
        } else {
            format!("{lo}-{hi}")
        }
    };
    let (cut, above) = (span(cut_lo, cut_hi), span(above_lo, above_hi));
    md.push_str(&format!(
        "\n## Why railwear is below ADAMS\n\nThe largest wear coefficient Table 4.3 allows in SI is K(2 Sy) = {k_max:.3e} m²/N. The column \"K needed for ADAMS\" is the coefficient that ADAMS' Table 5.4 rate would need at the N·|v_slip| power railwear computes for the same case: wherever it exceeds {k_max:.3e} m²/N, no contact pressure history can reproduce Table 5.4 with Table 4.3 read in SI and eq. 3.11 as written. The appendix post-processor (docs/results/errata.md §6) feeds |N| into K instead of sigma and scales C3 by 1e-3. The share of railwear's friction work done above the cutoff is {cut} % over the cases (column \"work above cutoff\"). The contact and wear parameters are the thesis' tables, not fitted to its results. The measured rates (Table 5.3) are {above} orders of magnitude above railwear's, most where the cube has room to tumble and impact: the gap the diagnosis ranks its effects on.\n"
    ));
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(
        out,
        splice_generated(std::fs::read_to_string(out).ok(), &md),
    )?;
    println!("wrote {}", out.display());
    Ok(())
}

const GENERATED_START: &str = "<!-- compare-rattle-box: start -->";
const GENERATED_END: &str = "<!-- compare-rattle-box: end -->";

/// `existing` with the text between the generated-section markers replaced by `section` (the
/// hand-written rest kept); a new file when there is none or it has no markers.
fn splice_generated(existing: Option<String>, section: &str) -> String {
    let block = format!("{GENERATED_START}\n{section}{GENERATED_END}\n");
    if let Some(text) = existing {
        if let (Some(a), Some(b)) = (text.find(GENERATED_START), text.find(GENERATED_END)) {
            if a < b {
                let tail = &text[b + GENERATED_END.len()..];
                return format!("{}{block}{}", &text[..a], tail.trim_start_matches('\n'));
            }
        }
    }
    format!("# Rattle box: railwear vs ADAMS (thesis Table 5.4) vs measured (Table 5.3)\n\n{block}")
}

/// `railwear campaign check <file>`: loads and validates a campaign; prints a summary (or, with
/// `json`, the campaign's JSON form). The error names the field and, for CSV data, the row.
pub fn campaign_check(file: &Path, json: bool, configs_dir: &Path) -> Result<()> {
    use crate::gap::Campaign;
    let campaign = Campaign::load(file).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    campaign
        .validate(configs_dir)
        .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    if json {
        println!("{}", serde_json::to_string_pretty(&campaign)?);
        return Ok(());
    }
    let (tests, specimens, increments, records) = campaign.counts();
    println!(
        "{}: valid (format {}), {tests} tests, {specimens} specimens, {increments} increments, \
         {records} accelerometer records",
        campaign.name, campaign.format_version
    );
    println!(
        "{:<8} {:<16} {:>6} {:>10} {:>10} {:>9}  mass loss per increment, mg (rate mg/h)",
        "test", "config", "k_rs", "drive", "incr. h", "res. mg"
    );
    for (ti, t) in campaign.tests.iter().enumerate() {
        let case = t.case(ti, configs_dir)?;
        let k_rs = crate::gap::campaign::CampaignTest::rattle_space_of(&case)
            .map_or("-".to_string(), |k| format!("{k:.3}"));
        let drive = t.drive.as_ref().map_or("config".to_string(), |d| {
            match (&d.profile, d.level_g, d.frequency_hz) {
                (Some(p), _, _) => p.clone(),
                (None, g, f) => format!(
                    "{}g@{}Hz",
                    g.map_or("-".into(), |g| g.to_string()),
                    f.map_or("-".into(), |f| f.to_string())
                ),
            }
        });
        let hours = t.increment_duration_s / crate::units::S_PER_H;
        for s in &t.specimens {
            let masses: Vec<String> = s
                .increments
                .iter()
                .map(|inc| {
                    inc.mass_loss_mg
                        .iter()
                        .map(|(c, m)| format!("{c} {m} ({:.4})", m / hours))
                        .collect::<Vec<_>>()
                        .join(", ")
                })
                .collect();
            println!(
                "{:<8} {:<16} {:>6} {:>10} {:>10.3} {:>9}  {}: {}",
                t.id,
                t.config,
                k_rs,
                drive,
                hours,
                t.scale_resolution_mg,
                s.id,
                masses.join(" | ")
            );
        }
    }
    Ok(())
}

/// The thesis campaign, built in (`railwear rig --base thesis`).
pub const BUILTIN_THESIS_CAMPAIGN: &str = include_str!("../../campaigns/thesis-rattle-box.toml");

/// `railwear rig`: writes `<out>/campaign.toml` (+ CSVs) and `<out>/truth.json`.
pub fn rig(
    base: &Path,
    effects: &[String],
    options: crate::gap::rig::RigOptions,
    out: &Path,
    configs_dir: &Path,
) -> Result<()> {
    use crate::gap::Campaign;
    let campaign = if base == Path::new("thesis") {
        Campaign::from_toml_str(BUILTIN_THESIS_CAMPAIGN, Path::new("."))?
    } else {
        Campaign::load(base).map_err(|e| anyhow::anyhow!("{}: {e}", base.display()))?
    };
    let (lib, hidden) = crate::gap::rig::parse_effects(effects)?;
    let options = crate::gap::rig::RigOptions {
        effects: lib,
        hidden,
        ..options
    };
    let (result, truth) =
        crate::gap::rig::run(&campaign, configs_dir, &options, &RunControl::silent())?;
    result.write_dir(out)?;
    std::fs::write(
        out.join("truth.json"),
        serde_json::to_string_pretty(&truth)?,
    )
    .with_context(|| format!("writing {}", out.join("truth.json").display()))?;
    let (tests, specimens, increments, records) = result.counts();
    println!(
        "wrote {} ({tests} tests, {specimens} specimens, {increments} increments, {records} \
         accelerometer records) and truth.json",
        out.join("campaign.toml").display()
    );
    for warning in resolution_warnings(&result, &truth) {
        eprintln!("warning: {warning}");
    }
    Ok(())
}

/// The 1-2-5 step at or below `x` (`x` > 0): 0.05 for 0.07, 0.2 for 0.2.
fn step_at_or_below(x: f64) -> f64 {
    let decade = 10f64.powf(x.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|step| *step <= x * (1.0 + 1e-12))
        .unwrap_or(decade)
}

/// One warning per test of a rig campaign where most of the model's masses (before noise and
/// rounding) are below its scale's resolution, so that most weighed masses read 0.
pub fn resolution_warnings(
    campaign: &crate::gap::Campaign,
    truth: &crate::gap::rig::Truth,
) -> Vec<String> {
    campaign
        .tests
        .iter()
        .filter_map(|test| {
            let t = truth.tests.iter().find(|t| t.id == test.id)?;
            let masses: Vec<f64> = t
                .model_mass_loss_mg
                .iter()
                .flat_map(|inc| inc.values().copied())
                .collect();
            resolution_warning(&test.id, test.scale_resolution_mg, masses)
        })
        .collect()
}

/// The warning for one test whose masses (mg) mostly fall below `resolution` (mg), naming the
/// 1-2-5 resolution at which nine in ten of them would read at least one step.
fn resolution_warning(test: &str, resolution: f64, mut masses: Vec<f64>) -> Option<String> {
    masses.retain(|m| m.is_finite());
    let below = masses.iter().filter(|m| **m < resolution).count();
    if masses.is_empty() || 2 * below <= masses.len() {
        return None;
    }
    masses.sort_by(f64::total_cmp);
    let positive: Vec<f64> = masses.iter().copied().filter(|m| *m > 0.0).collect();
    let advice = match positive.get(positive.len() / 10) {
        Some(m) => format!(
            "a scale resolution of {} mg would show nine in ten of them (or lengthen \
             increment_duration_s)",
            step_at_or_below(*m)
        ),
        None => "the model predicts no wear at all for this test".to_string(),
    };
    Some(format!(
        "test `{test}`: {below} of {} weighed masses are below the scale resolution \
         {resolution} mg and read as 0 (largest {:.3e} mg); {advice}",
        masses.len(),
        masses.last().copied().unwrap_or(0.0),
    ))
}

/// `railwear effects`: the effect library of the gap diagnosis (`gap::effects::LIBRARY`),
/// each effect with its parameters, units, bounds and reasons; `json` prints it as JSON.
/// The text is rendered from the entries' serialized form, so every field an entry has is
/// shown.
pub fn effects(json: bool) -> Result<()> {
    let library = serde_json::to_value(crate::gap::effects::LIBRARY)?;
    if json {
        println!("{}", serde_json::to_string_pretty(&library)?);
        return Ok(());
    }
    print!("{}", effects_text(&library));
    Ok(())
}

fn plain(value: &serde_json::Value) -> String {
    match value {
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Array(items) => items.iter().map(plain).collect::<Vec<_>>().join(", "),
        serde_json::Value::Null => "-".into(),
        other => other.to_string(),
    }
}

/// The library as text: one block per effect, its parameters as `name [min, max] unit
/// (default d): reason`.
fn effects_text(library: &serde_json::Value) -> String {
    let mut text = String::new();
    let empty = serde_json::Map::new();
    for effect in library.as_array().into_iter().flatten() {
        let fields = effect.as_object().unwrap_or(&empty);
        let name = fields.get("name").map_or("?".into(), plain);
        text.push_str(&format!("{name}\n"));
        for (key, value) in fields {
            if key == "name" || key == "parameters" {
                continue;
            }
            text.push_str(&format!("  {key}: {}\n", plain(value)));
        }
        let parameters = fields.get("parameters").and_then(|p| p.as_array());
        for (i, p) in parameters.into_iter().flatten().enumerate() {
            let get = |k: &str| p.get(k).map_or("-".into(), plain);
            let role = if i == 0 { " (magnitude)" } else { "" };
            text.push_str(&format!(
                "  parameter {}{role}: [{}, {}] {}, default {}\n    {}\n",
                get("name"),
                get("min"),
                get("max"),
                get("unit"),
                get("default"),
                get("reason"),
            ));
        }
        text.push('\n');
    }
    text
}

/// `railwear diagnose`: the report (summary or JSON) and its plots.
pub fn diagnose(
    file: &Path,
    json: bool,
    out: Option<&Path>,
    options: &crate::gap::diagnose::DiagnoseOptions,
    configs_dir: &Path,
) -> Result<()> {
    use crate::gap::Campaign;
    let campaign = Campaign::load(file)
        .and_then(|c| c.validate(configs_dir).map(|()| c))
        .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg} [{bar:30}] {pos}/{len} test simulations, eta {eta}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message("diagnosis");
    let cache = crate::gap::window::WindowCache::new();
    let (report, _) = crate::gap::diagnose::diagnose(
        &campaign,
        configs_dir,
        options,
        &RunControl::silent(),
        &cache,
        &|done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        },
    )?;
    bar.finish_and_clear();
    let dir = match out {
        Some(d) => d.to_path_buf(),
        None => file
            .parent()
            .unwrap_or_else(|| Path::new("."))
            .join("diagnosis"),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let text = serde_json::to_string_pretty(&report)?;
    std::fs::write(dir.join("report.json"), &text)
        .with_context(|| format!("writing {}", dir.join("report.json").display()))?;
    for (name, svg) in crate::gap::diagnose::plots::plots(&report) {
        std::fs::write(dir.join(&name), svg)
            .with_context(|| format!("writing {}", dir.join(&name).display()))?;
    }
    if json {
        println!("{text}");
        return Ok(());
    }
    println!("{}: {}", report.campaign, report.summary);
    if let Some(b) = &report.best_effect {
        for p in &b.parameters {
            println!("  {}", p.describe());
        }
        println!("  held out, per group (error before -> after, the rule's bound):");
        for g in &b.per_group {
            println!(
                "    {:<16} {:>8.2} -> {:>8.2}  bound {:>5.2}  {}",
                g.group,
                g.before,
                g.after,
                g.bound,
                if g.predicted {
                    "predicted".to_string()
                } else {
                    format!("NOT predicted (Holm-adjusted p = {:.1e})", g.p_adjusted)
                }
            );
        }
    }
    println!(
        "nominal: chi2 {:.1} on {:.1} dof (p = {:.2e}); held-out {}",
        report.nominal.chi2, report.nominal.dof, report.nominal.p_value, report.held_out
    );
    println!(
        "\n{:<28} {:>12} {:>10} {:>10} {:>9} {:>8} explains",
        "effect", "magnitude", "held-out", "gain", "lof p", "P(1st)"
    );
    for r in report.ranking.iter().chain(&report.pairs) {
        let mags: Vec<String> = r.magnitudes.iter().map(|m| format!("{m:.3e}")).collect();
        println!(
            "{:<28} {:>12} {:>10.2} {:>10.2} {:>9.2e} {:>8.2} {}",
            r.name,
            mags.join("+"),
            r.held_out_error,
            r.held_out_gain,
            r.residual_p_value,
            r.p_first,
            if r.explains { "yes" } else { "no" }
        );
    }
    println!("\nflagged groups (Holm, 5 %):");
    for g in report.location.groups.iter().filter(|g| g.flagged) {
        println!(
            "  {:<15} {:<50} mean residual {:+.2}, z {:+.1}, p_adj {:.1e}",
            g.by, g.label, g.mean_residual, g.z, g.p_adjusted
        );
    }
    println!("\n{}", report.location.energy_budget.table());
    println!("\n{}", plan_test::next_tests_text(&report.next_tests));
    println!("report and plots in {}", dir.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_follow_the_1_2_5_series() {
        assert_eq!(step_at_or_below(0.07), 0.05);
        assert_eq!(step_at_or_below(0.2), 0.2);
        assert_eq!(step_at_or_below(0.0031), 0.002);
        assert_eq!(step_at_or_below(12.0), 10.0);
    }

    #[test]
    fn a_test_whose_masses_mostly_read_zero_is_named_with_a_finer_resolution() {
        // Ten masses from 0.011 to 0.02 mg on a 0.05 mg scale: all read 0; the tenth
        // percentile, 0.012 mg, is first shown at a 0.01 mg step.
        let masses: Vec<f64> = (0..10).map(|i| 0.011 + 0.001 * f64::from(i)).collect();
        let w = resolution_warning("C", 0.05, masses).unwrap();
        assert!(w.contains("10 of 10"), "{w}");
        assert!(w.contains("resolution of 0.01 mg"), "{w}");
        // Most above the step: no warning.
        assert!(resolution_warning("C", 0.05, vec![0.01, 0.2, 0.3]).is_none());
        // No wear at all is said so.
        let w = resolution_warning("C", 0.05, vec![0.0, 0.0]).unwrap();
        assert!(w.contains("no wear"), "{w}");
    }

    #[test]
    fn the_effect_listing_names_every_effect_and_parameter() {
        let library = serde_json::to_value(crate::gap::effects::LIBRARY).unwrap();
        let text = effects_text(&library);
        for effect in crate::gap::effects::LIBRARY {
            assert!(text.contains(effect.name), "{}", effect.name);
            for p in effect.parameters {
                assert!(
                    text.contains(&format!("parameter {}", p.name)),
                    "{}",
                    p.name
                );
                assert!(text.contains(p.reason), "{}", p.name);
            }
        }
    }
}

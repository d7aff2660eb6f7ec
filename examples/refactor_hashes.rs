//! Development helper for behaviour-preserving refactors (issue 18): prints a SHA-256 of four
//! runs, so the same command before and after a change shows whether any result moved.
//!
//! - rattle box C, 2 s: summary JSON, tracks CSV and SVG plots;
//! - launcher-design, 2 s: the same;
//! - `railwear validate` (fast anchors): every anchor's measured value, bit for bit;
//! - a 3-point tolerance sweep of 0.5 s per point, one seed: the sweep summary JSON;
//! - the gap effects (printed first, it takes no simulation): every library and rig-only
//!   effect at magnitude 0, half and full, applied to rattle box C and the launcher (the
//!   edited case, or the error), its wear term evaluated on a grid of samples, and a wear-law
//!   effect carried to a sweep (`DiagnosedWearLaw::mechanism`).
//!
//! Usage: `cargo run --release --example refactor_hashes [configs-dir]`
use railwear::gap::effects::{Effect, SpecimenState, LIBRARY};
use railwear::gap::rig_effects::{HiddenEffect, RIG_ONLY};
use railwear::gap::tracks::{PressureBin, WearSample, WearTerm};
use railwear::models::case::load_case;
use railwear::pipeline::{simulate_job, sweep_job, CaseOutcome, DiagnosedWearLaw, RunControl};
use railwear::wear::law::WearLaw;
use sha2::{Digest, Sha256};
use std::path::Path;

fn hex(digest: impl AsRef<[u8]>) -> String {
    digest.as_ref().iter().map(|b| format!("{b:02x}")).collect()
}

fn outcome_hash(o: &CaseOutcome) -> String {
    let mut h = Sha256::new();
    h.update(o.summary.to_string());
    for s in &o.tracks {
        h.update(s.csv_line());
    }
    for (name, svg) in &o.plots {
        h.update(name);
        h.update(svg);
    }
    hex(h.finalize())
}

/// Every wear term's K and added rate on a grid of samples, bit for bit.
fn hash_term(h: &mut Sha256, term: &dyn WearTerm) {
    let law = WearLaw::table_4_3();
    let bins = [
        PressureBin {
            pressure_pa: 2.0e6,
            work_rate_w: 0.25,
        },
        PressureBin {
            pressure_pa: 9.0e8,
            work_rate_w: 0.5,
        },
    ];
    for pressure_pa in [0.0, 5.0e3, 2.0e4, 3.0e6, 6.0e7, 8.7e8, 2.0e9, f64::INFINITY] {
        for slip_speed_m_s in [0.0, 5.0e-4, 0.02, 0.3] {
            for slip_distance_m in [0.0, 40.0, 2.0e3, 5.0e4] {
                for points in [&bins[..0], &bins[..]] {
                    let s = WearSample {
                        pressure_pa,
                        normal_force_n: 12.5,
                        slip_speed_m_s,
                        slip_distance_m,
                        damping_power_w: 1.5,
                        penetration_rate_m_s: 0.04 * slip_speed_m_s - 1e-3,
                        yield_strength_pa: 435.0e6,
                        points,
                    };
                    let k = term.coefficient_m2_per_n(3.0e-16, &law, &s);
                    let added = term.added_volume_rate_m3_s(&law, &s);
                    h.update(k.to_bits().to_le_bytes());
                    h.update(added.to_bits().to_le_bytes());
                }
            }
        }
    }
}

fn effects_hash(configs: &Path) -> anyhow::Result<String> {
    let mut h = Sha256::new();
    let cases = [
        load_case(&configs.join("rattle-box-c.toml"))?,
        load_case(&configs.join("launcher-design.toml"))?,
    ];
    let state = SpecimenState {
        elapsed_h: 4.5,
        slip_distance_m: 3000.0,
    };
    let hardness_pa = 1.32e9;
    for info in LIBRARY.iter().chain(RIG_ONLY) {
        let p = &info.parameters[0];
        let extreme = if p.min < 0.0 { p.min } else { p.max };
        for magnitude in [0.0, 0.5 * p.max, extreme] {
            let text = format!("{}={magnitude}", info.name);
            h.update(&text);
            let Ok(effect) = Effect::parse(&text) else {
                let hidden = HiddenEffect::parse(&text)?;
                hash_term(&mut h, hidden.wear_term().as_ref());
                continue;
            };
            for case in &cases {
                let mut edited = case.clone();
                match effect.apply(&mut edited, &state, configs) {
                    Ok(()) => h.update(serde_json::to_string(&edited)?),
                    Err(e) => h.update(e.to_string()),
                }
            }
            if let Some(term) = effect.wear_term(hardness_pa)? {
                hash_term(&mut h, term.as_ref());
                let carried = DiagnosedWearLaw {
                    diagnosis: uuid::Uuid::nil(),
                    effect: effect.name.clone(),
                    parameters: effect.parameters.clone(),
                    verdict: "explained".into(),
                    note: String::new(),
                };
                match carried.mechanism(hardness_pa) {
                    Ok(m) => h.update(serde_json::to_string(&m)?),
                    Err(e) => h.update(e.to_string()),
                }
            }
        }
    }
    Ok(hex(h.finalize()))
}

fn main() -> anyhow::Result<()> {
    let configs = std::env::args().nth(1).unwrap_or_else(|| "configs".into());
    let configs = Path::new(&configs);
    println!("{:<16} {}", "effects", effects_hash(configs)?);
    let control = RunControl::silent();
    for config in ["rattle-box-c", "launcher-design"] {
        let params = serde_json::json!({
            "config": config,
            "overrides": {"simulation": {"duration_s": 2.0}},
            "seed": 7
        });
        let o = simulate_job(&params, configs, &control)?;
        println!(
            "{config:<16} {}  ({} track samples)",
            outcome_hash(&o),
            o.tracks.len()
        );
    }
    let mut h = Sha256::new();
    for a in railwear::validation::run_all(false, configs) {
        h.update(format!("{}={:e};", a.name, a.measured));
    }
    println!("{:<16} {}", "validate", hex(h.finalize()));
    let params = serde_json::json!({
        "points": 3,
        "seeds": 1,
        "overrides": {"simulation": {"duration_s": 0.5}},
        "seed": 11
    });
    let (summary, _) = sweep_job(&params, configs, &control)?;
    println!(
        "{:<16} {}",
        "sweep",
        hex(Sha256::digest(summary.to_string()))
    );
    Ok(())
}

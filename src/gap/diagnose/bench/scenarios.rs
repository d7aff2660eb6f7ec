//! The campaigns the bench draws: controls, each library effect from barely to clearly
//! detectable with its secondary parameters drawn within their bounds, pairs, rig-only effects;
//! and the rig's options for one of them.

use super::{BenchOptions, Scenario};
use crate::gap::diagnose::emulator::{applicable, effect_with};
use crate::gap::effects::{Acts, Effect, EffectInfo, LIBRARY};
use crate::gap::rig::RigOptions;
use crate::gap::rig_effects::{HiddenEffect, RIG_ONLY};
use crate::gap::{Campaign, GapError};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use std::collections::BTreeMap;
use std::path::Path;

/// Secondary parameters of `info` drawn uniformly within their bounds.
pub(super) fn draw_secondary(info: &EffectInfo, rng: &mut ChaCha20Rng) -> BTreeMap<String, f64> {
    info.parameters[1..]
        .iter()
        .map(|p| (p.name.to_string(), rng.gen_range(p.min..=p.max)))
        .collect()
}

pub(super) fn scenarios(
    base: &Campaign,
    configs_dir: &Path,
    o: &BenchOptions,
) -> Result<Vec<Scenario>, GapError> {
    let cases: Vec<_> = base
        .tests
        .iter()
        .enumerate()
        .map(|(ti, t)| t.case(ti, configs_dir))
        .collect::<Result<_, _>>()?;
    let lib = applicable(&cases, None)?;
    // Secondary parameters and pairs from their own stream.
    let mut draw = ChaCha20Rng::seed_from_u64(o.seed);
    draw.set_stream(2);
    type Drawn = (String, bool, Vec<Effect>, f64, f64);
    let mut list: Vec<Drawn> = Vec::new();
    let library_effect = |info: &EffectInfo, f: f64, rng: &mut ChaCha20Rng| {
        effect_with(info, f * info.parameters[0].max, &draw_secondary(info, rng))
    };
    let dynamics: Vec<&EffectInfo> = lib
        .iter()
        .copied()
        .filter(|e| e.acts == Acts::Dynamics)
        .collect();
    let wear: Vec<&EffectInfo> = lib
        .iter()
        .copied()
        .filter(|e| e.acts == Acts::WearLaw)
        .collect();
    for &noise in &o.noise_levels {
        for _ in 0..6 {
            list.push(("control".to_string(), true, Vec::new(), 0.0, noise));
        }
        for info in &lib {
            for f in &o.fractions {
                let e = library_effect(info, *f, &mut draw);
                list.push((
                    info.name.to_string(),
                    true,
                    vec![e],
                    f * info.parameters[0].max,
                    noise,
                ));
            }
        }
        for info in RIG_ONLY {
            for f in &o.fractions {
                list.push((
                    info.name.to_string(),
                    false,
                    Vec::new(),
                    f * info.parameters[0].max,
                    noise,
                ));
            }
        }
        // Pairs: a dynamics effect with a wear-law effect, and two dynamics effects.
        for kind in 0..2 {
            for _ in 0..o.pairs_per_kind {
                let Some(a) = dynamics.choose(&mut draw).copied() else {
                    continue;
                };
                let pool: Vec<&EffectInfo> = if kind == 0 {
                    wear.clone()
                } else {
                    dynamics
                        .iter()
                        .copied()
                        .filter(|d| d.name != a.name)
                        .collect()
                };
                let Some(b) = pool.choose(&mut draw).copied() else {
                    continue;
                };
                let (fa, fb) = (
                    *o.fractions.choose(&mut draw).unwrap_or(&0.3),
                    *o.fractions.choose(&mut draw).unwrap_or(&0.3),
                );
                let mut members = vec![
                    library_effect(a, fa, &mut draw),
                    library_effect(b, fb, &mut draw),
                ];
                let rank = |e: &Effect| LIBRARY.iter().position(|l| l.name == e.name);
                members.sort_by_key(rank);
                let name = members
                    .iter()
                    .map(|e| e.name.as_str())
                    .collect::<Vec<_>>()
                    .join("+");
                let m = members[0].magnitude();
                list.push((name, true, members, m, noise));
            }
        }
    }
    let mut rng = ChaCha20Rng::seed_from_u64(o.seed);
    list.shuffle(&mut rng);
    // Accelerometer records drawn per campaign after the order (so the order is the one
    // earlier benches drew): about half the campaigns weigh only.
    let mut records = ChaCha20Rng::seed_from_u64(o.seed ^ 0xacce1);
    let named = |truth: &str| {
        o.truth_filter.as_deref().is_none_or(|f| match f {
            "pairs" => truth.contains('+'),
            _ => truth.split('+').any(|t| t == f),
        })
    };
    Ok(list
        .into_iter()
        .enumerate()
        .map(
            |(i, (truth, in_library, effects, magnitude, noise_rel))| Scenario {
                truth,
                in_library,
                magnitude,
                effects,
                noise_rel,
                seed: o.seed.wrapping_mul(1000).wrapping_add(i as u64),
                accelerometers: records.gen_bool(o.records_share),
            },
        )
        .filter(|s| named(&s.truth))
        .filter(|s| o.only_seeds.is_empty() || o.only_seeds.contains(&s.seed))
        .take(o.campaigns)
        .collect())
}

pub(super) fn rig_options(
    s: &Scenario,
    o: &BenchOptions,
    noisy: bool,
) -> Result<RigOptions, GapError> {
    let mut r = RigOptions {
        noise_rel: if noisy { s.noise_rel } else { 0.0 },
        scatter_rel: if noisy { o.scatter_rel } else { 0.0 },
        seed: s.seed,
        window_s: o.rig_window_s,
        settle_s: o.rig_settle_s,
        segments_per_increment: 1,
        accelerometer_rate_hz: s.accelerometers.then_some(o.accelerometer_rate_hz),
        sensor_noise_m_s2: if noisy { o.sensor_noise_m_s2 } else { 0.0 },
        calibration_rel: if noisy {
            o.diagnose.accelerometer_calibration_rel
        } else {
            0.0
        },
        ..RigOptions::default()
    };
    if s.truth != "control" {
        if s.in_library {
            r.effects = s.effects.clone();
        } else {
            r.hidden.push(HiddenEffect::parse(&format!(
                "{}={}",
                s.truth, s.magnitude
            ))?);
        }
    }
    Ok(r)
}

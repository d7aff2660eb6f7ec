//! The candidates a next test must separate, read from a report: the one the verdict leans on
//! (the named effect or pair at its fitted values; with nothing named, the one that fits within
//! the noise, else the best held out) and its rivals (the nominal model, the candidates the
//! report cannot tell from it, then the next best held out among those that contend).

use super::super::report::{BestEffect, RankEntry, Report, Verdict};
use crate::gap::diagnose::emulator::effect_with;
use crate::gap::effects::{self, Effect};
use crate::gap::GapError;
use std::collections::BTreeMap;

/// Rivals besides the nominal model: with the leading candidate, up to four candidates to
/// predict per proposed setup, the "top 2-4".
pub const MAX_RIVALS: usize = 3;

/// A candidate at the values the diagnosis fitted.
#[derive(Debug, Clone, PartialEq)]
pub struct Leader {
    /// Effect, `a+b` for a pair, `none` for the nominal model.
    pub name: String,
    /// Its effects with every parameter.
    pub effects: Vec<Effect>,
}

/// Whether a report asks for a next test: not `explained` (a gap that is only partly
/// explained or not at all), or `explained` with candidates it cannot tell apart. A campaign
/// without a gap needs none.
pub fn wants_next_test(report: &Report) -> bool {
    match report.verdict {
        Verdict::NoGap => false,
        Verdict::Explained => !report.indistinguishable.is_empty(),
        Verdict::PartlyExplained | Verdict::NotExplained => true,
    }
}

/// The leading candidate and its rivals, or None when the report wants no next test or no
/// candidate contends (nothing to confirm). With nothing named, the leading candidate is the
/// one that fits every observation within the noise and removes the most of the gap (one test
/// carries it, so held out it gains nothing), else the best held out.
pub fn leaders(report: &Report) -> Result<Option<(Leader, Vec<Leader>)>, GapError> {
    if !wants_next_test(report) {
        return Ok(None);
    }
    let mut entries: Vec<&RankEntry> = report.ranking.iter().chain(&report.pairs).collect();
    entries.sort_by(|a, b| {
        b.held_out_log_likelihood
            .total_cmp(&a.held_out_log_likelihood)
    });
    // A candidate that fits every observation within the noise while removing some of the
    // gap, though held out it gains nothing (one test carries it: held out, nothing to fit it
    // on), is a contender the next test must confirm or refute.
    let fits = |e: &RankEntry| e.residual_p_value >= report.alpha && e.explained_share > 0.0;
    let contends = |e: &RankEntry| e.held_out_gain > 0.0 || fits(e);
    let focal = match &report.best_effect {
        Some(best) => named(best)?,
        None => {
            let fitting = entries
                .iter()
                .filter(|e| fits(e))
                .max_by(|a, b| a.explained_share.total_cmp(&b.explained_share));
            match fitting.or_else(|| entries.iter().find(|e| e.held_out_gain > 0.0)) {
                Some(e) => from_entry(e)?,
                None => return Ok(None),
            }
        }
    };
    let mut rivals = vec![Leader {
        name: "none".into(),
        effects: Vec::new(),
    }];
    let by_name = |name: &str| entries.iter().find(|e| e.name == name).copied();
    let indistinguishable = report.indistinguishable.iter().filter_map(|n| by_name(n));
    let next_best = entries.iter().copied().filter(|e| contends(e));
    for e in indistinguishable.chain(next_best) {
        if rivals.len() > MAX_RIVALS {
            break;
        }
        if e.name != focal.name && rivals.iter().all(|r| r.name != e.name) {
            rivals.push(from_entry(e)?);
        }
    }
    Ok(Some((focal, rivals)))
}

/// The named effect or pair at every value the report gives (fitted, measured or held at the
/// library default).
fn named(best: &BestEffect) -> Result<Leader, GapError> {
    let effects = best
        .name
        .split('+')
        .map(|member| {
            let values: BTreeMap<String, f64> = best
                .parameters
                .iter()
                .filter(|p| p.effect == member)
                .map(|p| (p.name.clone(), p.value))
                .collect();
            let info = library_info(member)?;
            let magnitude = values
                .get(info.parameters[0].name)
                .copied()
                .unwrap_or(info.parameters[0].default);
            Ok(effect_with(info, magnitude, &values))
        })
        .collect::<Result<Vec<_>, GapError>>()?;
    Ok(Leader {
        name: best.name.clone(),
        effects,
    })
}

/// A ranked candidate at its fitted magnitudes and the secondary values of the tables its fit
/// took (the library defaults where it took the default table).
fn from_entry(e: &RankEntry) -> Result<Leader, GapError> {
    let defaults = BTreeMap::new();
    let effects = e
        .name
        .split('+')
        .zip(&e.magnitudes)
        .enumerate()
        .map(|(i, (member, &m))| {
            let secondary = e.secondary.get(i).unwrap_or(&defaults);
            Ok(effect_with(library_info(member)?, m, secondary))
        })
        .collect::<Result<Vec<_>, GapError>>()?;
    Ok(Leader {
        name: e.name.clone(),
        effects,
    })
}

fn library_info(name: &str) -> Result<&'static effects::EffectInfo, GapError> {
    effects::info(name).ok_or_else(|| {
        GapError::field(
            "report.best_effect",
            format!("`{name}` is not an effect of the library"),
        )
    })
}

//! The truth's own fit, for the bench: the injected effects simulated in the emulator at their
//! drawn values (every secondary parameter, both members together), scored on the campaign's
//! data as any candidate is. It separates two reasons a diagnosis can miss: the library's
//! model of the truth does not fit the data within the noise (the emulator's window and
//! settle are not the rig's; the truth's lack-of-fit p-value is then small too), or it does
//! and the search did not reach it.

use super::emulator::Emulator;
use super::fit_problem::FitProblem;
use super::options::Simulating;
use super::stats;
use crate::gap::effects::{Acts, Effect};
use crate::gap::GapError;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// How the truth, simulated in the emulator, fits the campaign (full data).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthFit {
    /// Squared standardized residuals (a chi-square with `dof - parameters` degrees of
    /// freedom when the model holds).
    pub chi2: f64,
    /// Weighted observation count.
    pub dof: f64,
    /// Parameters the truth has (each effect's magnitude and secondary parameters, less those
    /// the campaign's data measure).
    pub parameters: usize,
    /// Lack-of-fit p-value.
    pub p_value: f64,
    /// Negative log-likelihood (the diagnosis' scale, calibration scales integrated out).
    pub nll: f64,
    /// Corrected Akaike information criterion of the full-data fit (the diagnosis' formula,
    /// with the truth's parameters counted).
    #[serde(default)]
    pub aicc: f64,
    /// The lack-of-fit test passes at the diagnosis' `alpha`.
    pub fits: bool,
    /// Chi-square and weighted count of each held-out group (test) alone: where a truth that
    /// does not fit misses.
    #[serde(default)]
    pub by_group: Vec<(String, f64, f64)>,
    /// The observations it misses most: test, increment, quantity, reading, prediction and
    /// standardized residual (the residual over its independent uncertainty, the channel's
    /// shared calibration scale left out), largest first.
    #[serde(default)]
    pub worst: Vec<String>,
}

/// How many of the largest standardized residuals [`TruthFit::worst`] lists.
const WORST: usize = 8;

/// The truth `effects` (one or two library effects, every parameter given) fitted as they
/// were drawn: each effect's table at its drawn secondary values holds its drawn magnitude
/// (simulated for a dynamics effect), and a pair is exact there (two dynamics effects
/// simulated together; a dynamics effect with a wear law, the law on the dynamics effect's
/// windows). None when the truth is empty, has more than two effects or holds an effect the
/// emulator does not tabulate (not applicable to the campaign).
pub fn truth_fit(
    sim: Simulating,
    emulator: &mut Emulator,
    effects: &[Effect],
) -> Result<Option<TruthFit>, GapError> {
    let (campaign, options, configs_dir, control, cache) = sim.parts();
    if effects.is_empty() || effects.len() > 2 {
        return Ok(None);
    }
    let mut spec: Vec<(usize, f64)> = Vec::with_capacity(effects.len());
    let mut parameters = 0;
    for e in effects {
        let info = e.info()?;
        let Some(default_table) = emulator
            .effects
            .iter()
            .position(|t| t.info.name == info.name && t.parameters.is_empty())
        else {
            return Ok(None);
        };
        // The secondary values as the emulator keys its variants: those off their defaults.
        let secondary: BTreeMap<String, f64> = info.parameters[1..]
            .iter()
            .filter_map(|p| {
                let v = e.parameters.get(p.name).copied().unwrap_or(p.default);
                (v != p.default).then(|| (p.name.to_string(), v))
            })
            .collect();
        let m = e.magnitude();
        let table = if secondary.is_empty() {
            default_table
        } else {
            emulator.add_variant(
                campaign,
                configs_dir,
                default_table,
                secondary,
                &[m],
                control,
                cache,
            )?
        };
        // A table held already (the defaults, or a variant the diagnosis built) gets the
        // drawn magnitude simulated.
        emulator.refine(
            campaign,
            configs_dir,
            &[(table, m)],
            control,
            cache,
            &|_, _| {},
        )?;
        // The magnitude and every secondary value but those the campaign's data measure.
        parameters += 1 + emulator.unmeasured_secondaries(info).len();
        spec.push((table, m));
    }
    if let [(a, ma), (b, mb)] = spec[..] {
        let acts = (emulator.effects[a].info.acts, emulator.effects[b].info.acts);
        match acts {
            (Acts::Dynamics, Acts::Dynamics) => {
                emulator.add_joint(campaign, configs_dir, (a, ma), (b, mb), control, cache)?;
            }
            (Acts::Dynamics, Acts::WearLaw) | (Acts::WearLaw, Acts::Dynamics) => {
                let (d, w) = if acts.0 == Acts::Dynamics {
                    (a, b)
                } else {
                    (b, a)
                };
                if emulator.pair(d, w).is_none() {
                    emulator.add_pair(campaign, configs_dir, d, w, control, cache)?;
                }
            }
            // Two wear laws multiply exactly on the nominal tracks.
            (Acts::WearLaw, Acts::WearLaw) => {}
        }
    }
    let problem = FitProblem::new(campaign, emulator, options);
    let t = problem.totals(&spec, &|_| true);
    let k = parameters as f64;
    let p_value = stats::lack_of_fit_p(t.r2, t.w, k);
    let by_group = (0..problem.groups)
        .map(|g| {
            let one = problem.totals(&spec, &|h| h == g);
            (problem.group_labels[g].clone(), one.r2, one.w)
        })
        .collect();
    let p = emulator.predict(&spec);
    let all = |_: usize| true;
    let mut z: Vec<(f64, String)> = problem
        .terms_of(&p, &spec, &all)
        .map(|(i, t)| {
            let o = &problem.obs[i];
            let z = t.residual / t.var.sqrt();
            let label = format!(
                "{} increment {} {}: {:.4e} read, {:.4e} predicted, z {:+.1}",
                problem.group_labels[problem.group[i]],
                o.increment + 1,
                o.quantity.label(),
                o.value,
                t.predicted,
                z
            );
            (z.abs(), label)
        })
        .collect();
    z.sort_by(|a, b| b.0.total_cmp(&a.0));
    let worst = z.into_iter().take(WORST).map(|(_, l)| l).collect();
    Ok(Some(TruthFit {
        chi2: t.r2,
        dof: t.w,
        parameters,
        p_value,
        nll: t.nll,
        aicc: stats::aicc(k, t.nll, t.w),
        fits: p_value >= options.alpha,
        by_group,
        worst,
    }))
}

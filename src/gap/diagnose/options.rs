//! How a diagnosis runs (its options, checked by one set of rules) and the constants of its
//! rules, with their reasons.

use super::emulator::EmulatorOptions;
use crate::cases::RunControl;
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use std::path::Path;

/// Held-out log-likelihood gain over the nominal model an effect must exceed to count as an
/// improvement beyond noise: a likelihood ratio of e² (about 7.4), the conventional "strong"
/// evidence threshold (Kass & Raftery 1995), on data the fit did not see.
pub const MIN_HELD_OUT_GAIN: f64 = 2.0;

/// Share of the nominal model's excess chi-square an explaining effect must remove: an effect
/// that passes the lack-of-fit test only because the gap was marginal, while accounting for
/// little of it, does not explain it.
pub const MIN_EXPLAINED_SHARE: f64 = 0.5;

/// Default rounds of adaptive refinement ([`DiagnoseOptions::refine_rounds`]).
pub const REFINE_ROUNDS: usize = 3;

/// Dynamics effects refined per round: those with the best held-out log-likelihood among the
/// ones that improve on the nominal.
pub const REFINE_CONTENDERS: usize = 3;

/// Held-out shrink below which a named effect only partly explains the gap
/// ([`Verdict::PartlyExplained`](super::Verdict::PartlyExplained)): it fits the training tests but predicts the held-out ones
/// little better than the nominal model.
pub const MIN_EXPLAINED_SHRINK: f64 = 0.2;

/// Effects whose secondary parameters are fitted when they lead and leave lack-of-fit: three,
/// so a pair of the two that are not first (a friction drift beside a cross-axis drive whose
/// single fit a fixture compliance follows) has both members' variants to choose from.
pub const SECONDARY_CONTENDERS: usize = 3;

/// Profile-likelihood drop of a 95 % interval for one parameter (chi-square 1 dof: 3.84 / 2).
pub const PROFILE_95: f64 = 1.920_729_410_347_062;

/// What the refinement steps and the truth's own fit simulate with: the campaign, the
/// diagnosis' options, the reference configs, the run's control and the window cache.
#[derive(Clone, Copy)]
pub struct Simulating<'a> {
    /// The campaign diagnosed.
    pub campaign: &'a Campaign,
    /// The diagnosis' options.
    pub options: &'a DiagnoseOptions,
    /// Directory of reference configs and profiles.
    pub configs_dir: &'a Path,
    /// Cancellation and progress of the simulations.
    pub control: &'a RunControl,
    /// Windows simulated already.
    pub cache: &'a WindowCache,
}

impl<'a> Simulating<'a> {
    /// `(campaign, options, configs_dir, control, cache)`.
    pub fn parts(
        self,
    ) -> (
        &'a Campaign,
        &'a DiagnoseOptions,
        &'a Path,
        &'a RunControl,
        &'a WindowCache,
    ) {
        (
            self.campaign,
            self.options,
            self.configs_dir,
            self.control,
            self.cache,
        )
    }
}

/// How the diagnosis runs.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// Simulations.
    pub emulator: EmulatorOptions,
    /// Significance level of the lack-of-fit tests and flags.
    pub alpha: f64,
    /// Bootstrap rounds.
    pub bootstrap_rounds: usize,
    /// Relative specimen scatter assumed when the campaign has no repeats (1 sigma).
    pub assumed_scatter_rel: f64,
    /// Relative standard uncertainty of the wear coefficient K (parameter uncertainty).
    pub k_rel_uncertainty: f64,
    /// Relative calibration uncertainty of an accelerometer's sensitivity (a mean square
    /// carries twice it).
    pub accelerometer_calibration_rel: f64,
    /// Rounds of adaptive refinement: each round simulates the dynamics effects that improve
    /// the held-out fit at the magnitudes their fits land on (on all tests and on every
    /// training fold) where the table holds no simulation yet, then fits again. 0 keeps the
    /// grid alone.
    pub refine_rounds: usize,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            emulator: EmulatorOptions::default(),
            alpha: 0.01,
            bootstrap_rounds: 500,
            assumed_scatter_rel: 0.3,
            k_rel_uncertainty: 0.1,
            accelerometer_calibration_rel: 0.02,
            refine_rounds: REFINE_ROUNDS,
        }
    }
}

/// The one set of rules for a diagnosis' options, for the CLI and the service alike; an error
/// names the option (`window_s`, `grid_points`, ...).
pub fn check_options(o: &DiagnoseOptions) -> Result<(), GapError> {
    let rule = GapError::require;
    rule(
        "alpha",
        o.alpha > 0.0 && o.alpha < 0.5,
        "must lie in (0, 0.5)",
    )?;
    rule(
        "bootstrap_rounds",
        (10..=100_000).contains(&o.bootstrap_rounds),
        "must lie in 10..=100000",
    )?;
    // The service's bounds (one set, with their reasons, in cases::limits).
    crate::cases::check_window_s(o.emulator.window_s)?;
    crate::cases::check_settle_s(o.emulator.settle_s)?;
    crate::cases::check_grid_points(o.emulator.grid_points)?;
    rule(
        "threads",
        (1..=64).contains(&o.emulator.threads),
        "must lie in 1..=64",
    )?;
    rule(
        "accelerometer_rate_hz",
        o.emulator.accelerometer_rate_hz.is_finite()
            && o.emulator.accelerometer_rate_hz >= 100.0
            && o.emulator.accelerometer_rate_hz <= 1e5,
        "must lie in [100, 1e5] Hz",
    )?;
    rule(
        "assumed_scatter_rel",
        o.assumed_scatter_rel.is_finite()
            && o.assumed_scatter_rel > 0.0
            && o.assumed_scatter_rel <= 2.0,
        "must lie in (0, 2]",
    )?;
    rule(
        "accelerometer_calibration_rel",
        o.accelerometer_calibration_rel.is_finite()
            && (0.0..=0.5).contains(&o.accelerometer_calibration_rel),
        "must lie in [0, 0.5]",
    )?;
    rule(
        "k_rel_uncertainty",
        o.k_rel_uncertainty.is_finite() && (0.0..=2.0).contains(&o.k_rel_uncertainty),
        "must lie in [0, 2]",
    )?;
    if let Some(effects) = &o.emulator.effects {
        each_once(effects)?;
    }
    Ok(())
}

/// The effects asked for, each once: the same effect twice is a typing error, not a pair.
fn each_once(effects: &[String]) -> Result<(), GapError> {
    for (i, name) in effects.iter().enumerate() {
        if let Some(first) = effects[..i].iter().position(|e| e == name) {
            return Err(GapError::field(
                format!("effects[{i}]"),
                format!("`{name}` is asked for twice (effects[{first}] names it already)"),
            ));
        }
    }
    Ok(())
}

fn model_name(m: crate::models::spec::ModelKind) -> &'static str {
    use crate::models::spec::ModelKind;
    match m {
        ModelKind::PersistentContact => "persistent_contact",
        ModelKind::RattleBox => "rattle_box",
        ModelKind::Launcher => "launcher",
    }
}

/// The effects asked for against the campaign they would diagnose: each a library effect,
/// asked for once, and applying to the model of every test (a launcher's spring preload loss
/// is not a candidate on a rattle-box campaign: the data cannot contradict a term the model
/// does not have, so it could only be dropped unseen). An error names `effects[i]`.
pub fn check_effects(
    campaign: &Campaign,
    effects: &[String],
    configs_dir: &Path,
) -> Result<(), GapError> {
    each_once(effects)?;
    let models: Vec<crate::models::spec::ModelKind> = campaign
        .tests
        .iter()
        .enumerate()
        .map(|(ti, t)| t.case(ti, configs_dir).map(|c| c.model))
        .collect::<Result<_, _>>()?;
    for (i, name) in effects.iter().enumerate() {
        let field = format!("effects[{i}]");
        let info = crate::gap::effects::info(name).ok_or_else(|| {
            let known: Vec<&str> = crate::gap::effects::LIBRARY
                .iter()
                .map(|e| e.name)
                .collect();
            GapError::field(
                field.clone(),
                format!("unknown effect `{name}` (known: {})", known.join(", ")),
            )
        })?;
        if let Some((ti, model)) = models
            .iter()
            .enumerate()
            .find(|(_, m)| !info.models.contains(m))
        {
            let applies: Vec<&str> = crate::gap::effects::LIBRARY
                .iter()
                .filter(|e| models.iter().all(|m| e.models.contains(m)))
                .map(|e| e.name)
                .collect();
            return Err(GapError::field(
                field,
                format!(
                    "`{name}` does not apply to test {}'s {} model (it models {}); effects that apply to this campaign: {}",
                    campaign.tests[ti].id,
                    model_name(*model),
                    info.models
                        .iter()
                        .map(|m| model_name(*m))
                        .collect::<Vec<_>>()
                        .join(", "),
                    applies.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod option_tests {
    use super::*;

    #[test]
    fn options_outside_their_bounds_are_refused_naming_the_option() {
        assert!(check_options(&DiagnoseOptions::default()).is_ok());
        let mut o = DiagnoseOptions::default();
        o.emulator.window_s = 0.04;
        let e = check_options(&o).unwrap_err();
        assert_eq!(e.field_path(), Some("window_s"), "{e}");
        assert!(e.to_string().contains("[0.05, 600] s"), "{e}");
        let mut o = DiagnoseOptions::default();
        o.emulator.grid_points = 13;
        assert_eq!(
            check_options(&o).unwrap_err().field_path(),
            Some("grid_points")
        );
        let mut o = DiagnoseOptions::default();
        o.emulator.effects = Some(vec![
            "third_body".into(),
            "cross_axis".into(),
            "third_body".into(),
        ]);
        let e = check_options(&o).unwrap_err();
        assert_eq!(e.field_path(), Some("effects[2]"), "{e}");
        assert!(e.to_string().contains("twice"), "{e}");
    }
}

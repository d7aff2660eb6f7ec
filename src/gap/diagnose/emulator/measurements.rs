//! What the campaign's own data measure (secondary values from the accelerometer records) and
//! the tables that agree with it.

use super::Emulator;
use crate::cases::RunControl;
use crate::gap::diagnose::measured::{measure, MeasuredValue};
use crate::gap::effects::{EffectInfo, ParameterInfo};
use crate::gap::window::WindowCache;
use crate::gap::{Campaign, GapError};
use std::collections::BTreeMap;
use std::path::Path;

impl Emulator {
    /// The measurement of `effect`'s `parameter`, if the campaign's data gave one.
    pub fn measured_value(&self, effect: &str, parameter: &str) -> Option<&MeasuredValue> {
        self.measured
            .iter()
            .find(|m| m.effect == effect && m.parameter == parameter)
    }

    /// The measurement that bounds table `t`'s magnitude (its effect's first parameter), if
    /// the campaign's records gave one: a fit keeps to its `band`.
    pub fn magnitude_measurement(&self, t: usize) -> Option<&MeasuredValue> {
        let info = self.effects.get(t)?.info;
        self.measured_value(info.name, info.parameters[0].name)
            .filter(|m| m.band.is_some())
    }

    /// The secondary parameters of `info` that no measurement fixes (a fit's to choose).
    pub fn unmeasured_secondaries(&self, info: &'static EffectInfo) -> Vec<&'static ParameterInfo> {
        info.parameters[1..]
            .iter()
            .filter(|p| self.measured_value(info.name, p.name).is_none())
            .collect()
    }

    /// Secondary parameters of table `t` off their defaults that no measurement fixes (the
    /// fit chose them).
    pub fn fitted_secondaries(&self, t: usize) -> usize {
        let table = &self.effects[t];
        table
            .parameters
            .keys()
            .filter(|p| self.measured_value(table.info.name, p).is_none())
            .count()
    }

    /// The campaign's measurements taken (`measure`), and for each a variant of its effect at
    /// the measured value on the default table's grid when no table agrees with it yet. A
    /// measurement whose effect is not tabulated is dropped.
    pub fn take_measurements(
        &mut self,
        campaign: &Campaign,
        configs_dir: &Path,
        control: &RunControl,
        cache: &WindowCache,
        calibration_rel: f64,
    ) -> Result<(), GapError> {
        let measured = measure(campaign, configs_dir, calibration_rel)?;
        self.measured.clear();
        for mv in measured {
            let Some(default) = (0..self.effects.len()).find(|&t| {
                self.effects[t].info.name == mv.effect && self.effects[t].parameters.is_empty()
            }) else {
                continue;
            };
            tracing::info!(
                effect = %mv.effect, parameter = %mv.parameter, value = mv.value, sd = mv.sd,
                "measured from the campaign's records"
            );
            let (value, parameter) = (mv.value, mv.parameter.clone());
            let primary = self.effects[default].info.parameters[0].name == parameter;
            self.measured.push(mv);
            // A magnitude's measurement bounds the fits (`magnitude_measurement`), no table.
            if primary {
                continue;
            }
            if !self
                .family(default)
                .iter()
                .any(|&t| self.agrees_with_measurements(t))
            {
                let grid: Vec<f64> = self.effects[default]
                    .magnitudes
                    .iter()
                    .copied()
                    .filter(|m| *m != 0.0)
                    .collect();
                self.add_variant(
                    campaign,
                    configs_dir,
                    default,
                    BTreeMap::from([(parameter, value)]),
                    &grid,
                    control,
                    cache,
                )?;
            }
        }
        Ok(())
    }

    /// Whether table `t`'s secondary values agree with every measurement of its effect's
    /// secondary parameters.
    pub fn agrees_with_measurements(&self, t: usize) -> bool {
        let table = &self.effects[t];
        self.measured
            .iter()
            .filter(|m| m.effect == table.info.name && m.parameter != table.info.parameters[0].name)
            .all(|m| m.agrees(table.parameter(&m.parameter)))
    }
}

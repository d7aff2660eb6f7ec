//! One candidate's numbers (held out per group, full-data fit, criteria) and the rules that
//! say whether it explains the gap, cleanly or only partly.

use super::emulator::Emulator;
use super::options::{MIN_EXPLAINED_SHARE, MIN_EXPLAINED_SHRINK, MIN_HELD_OUT_GAIN};

/// One candidate's numbers.
#[derive(Debug, Clone)]
pub(super) struct Candidate {
    /// Effects (family indices), for its name.
    pub(super) families: Vec<usize>,
    /// Full-data fit: (table, magnitude) per effect.
    pub(super) spec: Vec<(usize, f64)>,
    /// The fit on each training fold (the held-out predictions use them).
    pub(super) fold_specs: Vec<Vec<(usize, f64)>>,
    pub(super) held_nll: Vec<f64>,
    pub(super) held_r2: Vec<f64>,
    pub(super) held_w: Vec<f64>,
    pub(super) aicc: f64,
    pub(super) bic: f64,
    pub(super) residual_p: f64,
    pub(super) chi2: f64,
    pub(super) dof: f64,
    /// Parameters fitted (full data).
    pub(super) k: f64,
    pub(super) alpha: f64,
}

impl Candidate {
    pub(super) fn held_ll(&self) -> f64 {
        -self.held_nll.iter().sum::<f64>()
    }

    pub(super) fn held_error(&self) -> f64 {
        (self.held_r2.iter().sum::<f64>() / self.held_w.iter().sum::<f64>().max(1e-300)).sqrt()
    }

    pub(super) fn magnitudes(&self) -> Vec<f64> {
        self.spec.iter().map(|s| s.1).collect()
    }

    /// The table of a single effect's full-data fit.
    pub(super) fn table(&self) -> usize {
        self.spec.first().map_or(0, |s| s.0)
    }

    pub(super) fn explained_share(&self, nominal: &Candidate) -> f64 {
        let excess = nominal.chi2 - nominal.dof;
        if excess > 0.0 {
            (nominal.chi2 - self.chi2) / excess
        } else {
            0.0
        }
    }

    /// Explains, but fitted at a magnitude bound or with a held-out shrink under
    /// [`MIN_EXPLAINED_SHRINK`] (what `partly_explained` reports).
    pub(super) fn only_partly(&self, nominal: &Candidate, emulator: &Emulator) -> bool {
        let at_bound = self.spec.iter().any(|&(t, m)| {
            let b = emulator.effects[t].bound_for(m);
            m != 0.0 && (m - b).abs() <= 1e-9 * b.abs()
        });
        let before = nominal.held_error();
        let shrink = if before > 0.0 {
            1.0 - self.held_error() / before
        } else {
            0.0
        };
        at_bound || !(shrink >= MIN_EXPLAINED_SHRINK)
    }

    pub(super) fn explains(&self, nominal: &Candidate) -> bool {
        self.held_ll() - nominal.held_ll() > MIN_HELD_OUT_GAIN
            && self.residual_p >= self.alpha
            && self.explained_share(nominal) >= MIN_EXPLAINED_SHARE
    }

    /// Explains, and not only partly: what lets a single stand without pairs or profiles.
    pub(super) fn explains_cleanly(&self, nominal: &Candidate, emulator: &Emulator) -> bool {
        self.explains(nominal) && !self.only_partly(nominal, emulator)
    }
}

/// Requests `(table, magnitude)` of a candidate's simulated tables at its full-data and every
/// fold's fitted magnitudes.
pub(super) fn requests_of(emulator: &Emulator, c: &Candidate) -> Vec<(usize, f64)> {
    std::iter::once(&c.spec)
        .chain(c.fold_specs.iter())
        .flat_map(|s| s.iter().copied())
        .filter(|(t, m)| *m != 0.0 && emulator.effects[*t].simulated)
        .collect()
}

//! One anchor of `railwear validate`: what is checked, the number physics or the thesis fixes,
//! the number this build measures, the tolerance and the verdict.

use serde::Serialize;

/// One anchor's outcome.
#[derive(Debug, Clone, Serialize)]
pub struct Anchor {
    /// What is checked.
    pub name: String,
    /// Where the expected number comes from.
    pub source: String,
    /// Unit of expected/measured/tolerance.
    pub unit: String,
    /// Expected value.
    pub expected: f64,
    /// Measured value.
    pub measured: f64,
    /// Admissible |measured - expected|.
    pub tolerance: f64,
    /// Verdict.
    pub pass: bool,
}

/// An anchor with its verdict: `measured` finite and within `tolerance` of `expected`.
pub fn anchor(
    name: &str,
    source: &str,
    unit: &str,
    expected: f64,
    measured: f64,
    tolerance: f64,
) -> Anchor {
    Anchor {
        name: name.into(),
        source: source.into(),
        unit: unit.into(),
        expected,
        measured,
        tolerance,
        pass: measured.is_finite() && (measured - expected).abs() <= tolerance,
    }
}

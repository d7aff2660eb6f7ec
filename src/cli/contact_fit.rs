//! `railwear contact-fit`: the IMPACT stiffness k and exponent e of a sphere on a flat, fitted
//! to a quasistatic model of thesis 2.3.1 ([`crate::contact_models::impact_fit()`]), printed with
//! the fitted range and the weighting.

use crate::contact_models::{impact_fit, ContactModelError, FitSpace, ImpactFit, ImpactFitSpec};
use crate::contact_models::{QuasistaticModel, SphereOnFlat};
use crate::field_error::FieldError;
use crate::units::M_PER_MM;
use crate::wear::Material;
use anyhow::Result;

/// The command line's materials: one for both bodies, with the flat's own values where given.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MaterialFlags {
    /// Young's modulus E, Pa.
    pub youngs_modulus_pa: Option<f64>,
    /// Poisson's ratio nu.
    pub poisson_ratio: Option<f64>,
    /// Yield strength S_y, Pa.
    pub yield_strength_pa: Option<f64>,
}

impl MaterialFlags {
    /// `base` with the values given here.
    fn apply(&self, mut base: Material) -> Material {
        if let Some(x) = self.youngs_modulus_pa {
            base.youngs_modulus_pa = x;
        }
        if let Some(x) = self.poisson_ratio {
            base.poisson_ratio = x;
        }
        if let Some(x) = self.yield_strength_pa {
            base.yield_strength_pa = x;
        }
        base
    }
}

/// The parsed command line of `contact-fit`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFitArgs {
    /// The model fitted.
    pub model: QuasistaticModel,
    /// Sphere radius, m.
    pub radius_m: f64,
    /// Both bodies' material over 7075-T73.
    pub material: MaterialFlags,
    /// The flat's own material over that.
    pub flat: MaterialFlags,
    /// Upper end of the fitted range, m.
    pub max_interference_m: f64,
    /// Samples of the fit.
    pub samples: usize,
    /// Residuals on force or on ln F.
    pub space: FitSpace,
}

/// Parses `--model`: a model name ([`QuasistaticModel::name`], `-` for `_` allowed).
pub fn parse_model(text: &str) -> std::result::Result<QuasistaticModel, String> {
    QuasistaticModel::from_name(text).ok_or_else(|| {
        let names: Vec<&str> = QuasistaticModel::ALL.iter().map(|m| m.name()).collect();
        format!("must be one of {}", names.join(", "))
    })
}

/// Parses `--fit-space`: `linear` (residuals on force) or `log` (on ln F).
pub fn parse_fit_space(text: &str) -> std::result::Result<FitSpace, String> {
    serde_json::from_value(serde_json::Value::from(text))
        .map_err(|_| "must be linear (least squares on force) or log (on ln F)".to_string())
}

/// The command-line flag a field of [`ImpactFitSpec`] comes from: `sphere.x` is `--x` (the
/// material of both bodies), `flat.x` is `--flat-x`, anything else `--field`.
fn flag_of(field: &str) -> String {
    let flag = field.strip_prefix("sphere.").unwrap_or(field);
    format!("--{}", flag.replace(['.', '_'], "-"))
}

/// Runs the fit; the error of a bad value names its flag and the rule.
pub fn contact_fit_report(args: &ContactFitArgs) -> Result<ImpactFit> {
    let both = args.material.apply(Material::aluminium_7075_t73());
    let spec = ImpactFitSpec {
        model: args.model,
        radius_m: args.radius_m,
        sphere: both,
        flat: args.flat.apply(both),
        max_interference_m: args.max_interference_m,
        samples: args.samples,
        space: args.space,
    };
    impact_fit(&spec).map_err(|e| match e {
        ContactModelError::Invalid(FieldError { field, rule }) => {
            anyhow::anyhow!("{} {rule}", flag_of(&field))
        }
        other => anyhow::anyhow!(other),
    })
}

/// `railwear contact-fit`: prints the summary, or the fit's JSON with `json`.
pub fn contact_fit(args: &ContactFitArgs, json: bool) -> Result<()> {
    let fit = contact_fit_report(args)?;
    if json {
        println!("{}", serde_json::to_string_pretty(&fit)?);
    } else {
        print!("{}", summary(&fit));
    }
    Ok(())
}

/// The human summary of a fit.
pub fn summary(fit: &ImpactFit) -> String {
    let s = &fit.spec;
    let softer = SphereOnFlat {
        radius_m: s.radius_m,
        sphere: s.sphere,
        flat: s.flat,
    }
    .yield_strength_pa();
    let mm = |x_m: f64| x_m / M_PER_MM;
    let mut out = String::new();
    out += &format!(
        "IMPACT spring k w^e (eq. 2.7) fitted to {}\n",
        s.model.title()
    );
    out += &format!(
        "sphere R = {} mm on a flat: E* = {:.4} GPa (eq. 2.6), S_y = {:.0} MPa (softer body), \
         w_c = {:.5} mm (eq. 2.17)\n",
        mm(s.radius_m),
        fit.effective_modulus_pa / 1e9,
        softer / 1e6,
        mm(fit.critical_interference_m)
    );
    out += &format!(
        "range:     w from {:.6} mm to {} mm, {} samples {}\n",
        mm(fit.range.min_interference_m),
        mm(fit.range.max_interference_m),
        fit.range.samples,
        fit.range.spacing
    );
    out += &format!("weighting: {}\n", fit.weighting);
    out += &format!(
        "k = {:.6e} N/mm^e  ({:.6e} N/m^e)\ne = {:.6}\n",
        fit.stiffness_n_per_mm_e, fit.stiffness_si, fit.exponent
    );
    out += &format!(
        "rms residual / max force = {:.3e}\n",
        fit.rms_residual_over_max_force
    );
    out += &format!(
        "case file: [..contact] stiffness_n_per_mm_e = {:.6e}, exponent = {:.6} (the exponent \
         depends on range and weighting: quote them with it)\n",
        fit.stiffness_n_per_mm_e, fit.exponent
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_map_to_their_flags() {
        assert_eq!(flag_of("radius_m"), "--radius-m");
        assert_eq!(flag_of("sphere.poisson_ratio"), "--poisson-ratio");
        assert_eq!(
            flag_of("flat.youngs_modulus_pa"),
            "--flat-youngs-modulus-pa"
        );
        assert_eq!(flag_of("max_interference_m"), "--max-interference-m");
    }
}

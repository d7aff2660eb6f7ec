//! The one error of a value that breaks a rule: the field's name and the rule in words.
//!
//! Spec validation, the libraries' argument checks and the service's submit checks all carry
//! it (each error enum wraps it with its own wording); the HTTP edge turns it into a 422
//! problem naming the field (`http::problem`).

/// A field that breaks a rule. `field` is the field's name, a dotted path where the caller
/// knows where it sits (`rattle_box.friction.mu_dynamic`); `rule` is the rule in words, with
/// the offending value where useful.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("field `{field}` {rule}")]
pub struct FieldError {
    /// Name or dotted path of the offending field.
    pub field: String,
    /// The rule broken, in words.
    pub rule: String,
}

impl FieldError {
    /// `field` breaks `rule`.
    pub fn new(field: impl Into<String>, rule: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            rule: rule.into(),
        }
    }

    /// `value` must be a finite number > 0; the error names `field` and that rule.
    pub fn positive(field: &str, value: f64) -> Result<(), Self> {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(Self::new(field, "must be a finite number > 0"))
        }
    }

    /// `value` must be a finite number >= 0; the error names `field` and that rule.
    pub fn non_negative(field: &str, value: f64) -> Result<(), Self> {
        if value.is_finite() && value >= 0.0 {
            Ok(())
        } else {
            Err(Self::new(field, "must be a finite number >= 0"))
        }
    }

    /// The same error with its field placed under `prefix` (`prefix.field`; unchanged when
    /// `prefix` is empty), for a nested value reported at its path.
    pub fn at(mut self, prefix: &str) -> Self {
        if !prefix.is_empty() {
            self.field = format!("{prefix}.{}", self.field);
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positive_and_non_negative_name_the_field_and_the_rule() {
        assert_eq!(FieldError::positive("k", 1e-12), Ok(()));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(
                FieldError::positive("k", bad),
                Err(FieldError::new("k", "must be a finite number > 0"))
            );
        }
        assert_eq!(FieldError::non_negative("c", 0.0), Ok(()));
        for bad in [-1e-300, f64::NAN, f64::NEG_INFINITY] {
            assert_eq!(
                FieldError::non_negative("c", bad),
                Err(FieldError::new("c", "must be a finite number >= 0"))
            );
        }
    }

    #[test]
    fn names_the_field_and_nests_under_a_prefix() {
        let e = FieldError::new("mu_static", "must be >= 0");
        assert_eq!(e.to_string(), "field `mu_static` must be >= 0");
        assert_eq!(e.clone().at("").field, "mu_static");
        assert_eq!(
            e.at("rattle_box.friction").field,
            "rattle_box.friction.mu_static"
        );
    }
}

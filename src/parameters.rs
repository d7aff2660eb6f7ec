//! Named model parameters described for users (name, unit, bounds, default and the reason for
//! them) and typed for the code that uses them.
//!
//! A closed set of options with a few numeric parameters each (the gap diagnosis' effects, the
//! wear mechanisms they fit) is read from a name-to-value map at the edge. `parameter_struct!`
//! declares the typed struct and its [`ParameterInfo`] table in one place: a field's name is
//! the parameter's name, so the table users read and the code that applies the values cannot
//! drift apart, and reading the map refuses a missing or unknown name instead of taking 0.

use crate::field_error::FieldError;
use serde::Serialize;
use std::collections::BTreeMap;

/// One parameter: what users see (`railwear effects`) and what parsing checks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ParameterInfo {
    /// Name, with its unit.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Smallest physical value.
    pub min: f64,
    /// Largest physical value.
    pub max: f64,
    /// Value when not given (the magnitude's default is its nominal 0).
    pub default: f64,
    /// Why these bounds: literature, thesis, or estimate.
    pub reason: &'static str,
}

/// A typed set of named parameters (declared with `parameter_struct!`).
pub trait Parameters: Sized + Copy {
    /// Name of what the parameters belong to (an effect's library name).
    const NAME: &'static str;
    /// The parameters, in the struct's field order (the first is the magnitude).
    const PARAMETERS: &'static [ParameterInfo];

    /// Reads every parameter from `values`. A missing name, or a name that is not a parameter,
    /// is an error whose field is that name (callers place it under their path).
    fn from_values(values: &BTreeMap<String, f64>) -> Result<Self, FieldError>;

    /// The values by name.
    fn values(&self) -> BTreeMap<String, f64>;

    /// The first parameter's value (an effect's magnitude).
    fn magnitude(&self) -> f64;

    /// Every parameter at its default.
    fn defaults() -> Self {
        let values = Self::PARAMETERS
            .iter()
            .map(|p| (p.name.to_string(), p.default))
            .collect();
        match Self::from_values(&values) {
            Ok(p) => p,
            // The table is the struct's own: every name is there.
            Err(e) => unreachable!("{}: {e}", Self::NAME),
        }
    }
}

/// Refuses a name of `values` that is not one of `parameters`.
#[doc(hidden)]
pub fn refuse_unknown(
    values: &BTreeMap<String, f64>,
    parameters: &[ParameterInfo],
) -> Result<(), FieldError> {
    match values
        .keys()
        .find(|k| !parameters.iter().any(|p| p.name == k.as_str()))
    {
        Some(unknown) => Err(FieldError::new(unknown.clone(), "is not a parameter")),
        None => Ok(()),
    }
}

/// The value of `name` in `values`, or an error naming it.
#[doc(hidden)]
pub fn required(values: &BTreeMap<String, f64>, name: &str) -> Result<f64, FieldError> {
    values
        .get(name)
        .copied()
        .ok_or_else(|| FieldError::new(name, "is required"))
}

/// Declares a struct of `f64` parameters, its [`Parameters`] implementation and its
/// [`ParameterInfo`] table from one list: each field with its unit, bounds, default and the
/// reason for them.
///
/// ```ignore
/// parameter_struct! {
///     /// (k) Local-pressure Archard.
///     pub struct LocalPressureParameters = "local_pressure" {
///         share {
///             unit: "1",
///             min: 0.0, max: 1.0, default: 0.0,
///             reason: "every share between is allowed",
///         },
///     }
/// }
/// ```
macro_rules! parameter_struct {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident = $effect:literal {
            $(
                $field:ident {
                    unit: $unit:literal,
                    min: $min:expr,
                    max: $max:expr,
                    default: $default:expr,
                    reason: $reason:literal $(,)?
                }
            ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        $vis struct $name {
            $(
                #[doc = concat!("Unit: ", $unit, ". ", $reason)]
                pub $field: f64,
            )+
        }

        impl $crate::parameters::Parameters for $name {
            const NAME: &'static str = $effect;
            const PARAMETERS: &'static [$crate::parameters::ParameterInfo] = &[$(
                $crate::parameters::ParameterInfo {
                    name: stringify!($field),
                    unit: $unit,
                    min: $min,
                    max: $max,
                    default: $default,
                    reason: $reason,
                },
            )+];

            fn from_values(
                values: &std::collections::BTreeMap<String, f64>,
            ) -> Result<Self, $crate::field_error::FieldError> {
                $crate::parameters::refuse_unknown(values, Self::PARAMETERS)?;
                Ok(Self {
                    $($field: $crate::parameters::required(values, stringify!($field))?,)+
                })
            }

            fn values(&self) -> std::collections::BTreeMap<String, f64> {
                [$((stringify!($field).to_string(), self.$field)),+].into_iter().collect()
            }

            fn magnitude(&self) -> f64 {
                [$(self.$field),+][0]
            }
        }
    };
}
pub(crate) use parameter_struct;

#[cfg(test)]
mod tests {
    use super::*;

    parameter_struct! {
        /// Two parameters.
        struct Pair = "pair" {
            first { unit: "m", min: 0.0, max: 1.0, default: 0.0, reason: "a" },
            second { unit: "s", min: 1.0, max: 2.0, default: 1.5, reason: "b" },
        }
    }

    #[test]
    fn names_are_the_fields_and_a_wrong_name_is_refused() {
        let names: Vec<&str> = Pair::PARAMETERS.iter().map(|p| p.name).collect();
        assert_eq!(names, ["first", "second"]);
        let d = Pair::defaults();
        assert_eq!((d.first, d.second, d.magnitude()), (0.0, 1.5, 0.0));
        assert_eq!(Pair::from_values(&d.values()), Ok(d));
        let mut values = d.values();
        values.remove("second");
        assert_eq!(Pair::from_values(&values).unwrap_err().field, "second");
        values.insert("second".into(), 1.0);
        values.insert("secnod".into(), 1.0);
        let e = Pair::from_values(&values).unwrap_err();
        assert_eq!(
            (e.field.as_str(), e.rule.as_str()),
            ("secnod", "is not a parameter")
        );
    }
}

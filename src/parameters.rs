//! Named model parameters described for users (name, unit, bounds, default and the reason for
//! them) and typed for the code that uses them, and the one bound mechanism every number of a
//! case uses: a [`Bound`] (a range with its unit and reason) declared beside the field it
//! bounds, checked on the typed value by [`Bounded::check_bounds`] at the field's path
//! ([`FieldPath`]).
//!
//! A closed set of options with a few numeric parameters each (the gap diagnosis' effects, the
//! wear mechanisms they fit) is read from a name-to-value map at the edge. `parameter_struct!`
//! declares the typed struct and its [`ParameterInfo`] table in one place: a field's name is
//! the parameter's name, so the table users read and the code that applies the values cannot
//! drift apart, and reading the map refuses a missing or unknown name instead of taking 0.

use crate::field_error::FieldError;
use serde::Serialize;
use std::collections::BTreeMap;

/// A closed or half-open range of one number, with its unit and the physical reason: declared
/// as a `const` beside the field it bounds (a case's spec structs, a calibration record) and
/// carried by every [`ParameterInfo`] ([`ParameterInfo::bound`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Bound {
    /// Lower end.
    pub min: f64,
    /// Whether `min` itself is refused.
    pub min_open: bool,
    /// Upper end (inclusive).
    pub max: f64,
    /// Unit of the field, as its name says (empty: dimensionless).
    pub unit: &'static str,
    /// Why values outside the range are not physical.
    pub reason: &'static str,
}

impl Bound {
    /// The closed range `[min, max]` in `unit`, for `reason`.
    pub const fn new(min: f64, max: f64, unit: &'static str, reason: &'static str) -> Self {
        Self {
            min,
            min_open: false,
            max,
            unit,
            reason,
        }
    }

    /// The same range with `min` itself refused: `(min, max]`.
    pub const fn open_min(mut self) -> Self {
        self.min_open = true;
        self
    }

    /// Whether `v` is a finite number inside the range.
    pub fn admits(&self, v: f64) -> bool {
        v.is_finite()
            && v <= self.max
            && if self.min_open {
                v > self.min
            } else {
                v >= self.min
            }
    }

    /// The rule in words: `must lie in [min, max] unit: reason`.
    pub fn rule(&self) -> String {
        let open = if self.min_open { "(" } else { "[" };
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!(
            "must lie in {open}{:e}, {:e}]{unit}: {}",
            self.min, self.max, self.reason
        )
    }

    /// `v` inside the range, or the error naming `field` with the rule and the value.
    pub fn check(&self, field: &str, v: f64) -> Result<(), FieldError> {
        if self.admits(v) {
            Ok(())
        } else {
            Err(FieldError::new(field, format!("{}, got {v}", self.rule())))
        }
    }
}

/// Where a bounds check stands in a typed value (`rattle_box.friction`), and, when asked for,
/// every number it has checked, by path, with its bound (so a test can show that each numeric
/// field of a case is bounded, and refuse a value outside each bound).
#[derive(Debug, Clone, Default)]
pub struct FieldPath {
    path: String,
    checked: Option<Vec<(String, Bound)>>,
}

impl FieldPath {
    /// The path `at` (empty: the value's root).
    pub fn new(at: &str) -> Self {
        Self {
            path: at.to_string(),
            checked: None,
        }
    }

    /// [`FieldPath::new`] that records every number it checks ([`FieldPath::checked`]).
    pub fn recording(at: &str) -> Self {
        Self {
            path: at.to_string(),
            checked: Some(Vec::new()),
        }
    }

    /// The paths of the numbers checked so far, each with its bound (empty unless
    /// [`FieldPath::recording`]).
    pub fn checked(&self) -> &[(String, Bound)] {
        self.checked.as_deref().unwrap_or_default()
    }

    /// The current path.
    pub fn as_str(&self) -> &str {
        &self.path
    }

    /// Runs `f` at the path of the field `name` below the current one.
    pub fn field<T>(
        &mut self,
        name: &str,
        f: impl FnOnce(&mut Self) -> Result<T, FieldError>,
    ) -> Result<T, FieldError> {
        let len = self.path.len();
        if !self.path.is_empty() {
            self.path.push('.');
        }
        self.path.push_str(name);
        let out = f(self);
        self.path.truncate(len);
        out
    }

    /// Runs `f` at the path of item `index` of the current (array) field.
    pub fn item<T>(
        &mut self,
        index: usize,
        f: impl FnOnce(&mut Self) -> Result<T, FieldError>,
    ) -> Result<T, FieldError> {
        let len = self.path.len();
        self.path.push_str(&format!("[{index}]"));
        let out = f(self);
        self.path.truncate(len);
        out
    }

    /// The current field's own number against `bound`.
    pub fn this(&mut self, v: f64, bound: &Bound) -> Result<(), FieldError> {
        if let Some(checked) = &mut self.checked {
            checked.push((self.path.clone(), *bound));
        }
        bound.check(&self.path, v)
    }

    /// The number field `name` against `bound`.
    pub fn number(&mut self, name: &str, v: f64, bound: &Bound) -> Result<(), FieldError> {
        self.field(name, |at| at.this(v, bound))
    }

    /// Each number of the list (or vector) field `name` against `bound`, named by its index.
    pub fn numbers(&mut self, name: &str, vs: &[f64], bound: &Bound) -> Result<(), FieldError> {
        self.field(name, |at| {
            vs.iter()
                .enumerate()
                .try_for_each(|(i, v)| at.item(i, |at| at.this(*v, bound)))
        })
    }

    /// The optional number field `name` against `bound` when it is given.
    pub fn optional(
        &mut self,
        name: &str,
        v: Option<f64>,
        bound: &Bound,
    ) -> Result<(), FieldError> {
        v.map_or(Ok(()), |v| self.number(name, v, bound))
    }

    /// The text field `name`: at most `max` characters and no control characters (a
    /// `paragraph` may hold line breaks and tabs).
    pub fn text(
        &mut self,
        name: &str,
        s: &str,
        max: usize,
        paragraph: bool,
    ) -> Result<(), FieldError> {
        self.field(name, |at| {
            let chars = s.chars().count();
            if chars > max {
                return Err(FieldError::new(
                    at.as_str(),
                    format!("has {chars} characters; at most {max} are kept"),
                ));
            }
            let allowed = |c: char| paragraph && matches!(c, '\n' | '\t');
            if s.chars().any(|c| c.is_control() && !allowed(c)) {
                return Err(FieldError::new(
                    at.as_str(),
                    "must not contain control characters",
                ));
            }
            Ok(())
        })
    }

    /// The typed child `value` at the field `name`.
    pub fn child<T: Bounded + ?Sized>(&mut self, name: &str, value: &T) -> Result<(), FieldError> {
        self.field(name, |at| value.check_bounds(at))
    }
}

/// A typed value whose numbers have bounds, declared beside its fields: it checks its own
/// fields and calls its children's checks, each at its path.
pub trait Bounded {
    /// Every number of `self` inside its bound; the error names the first one outside, at its
    /// path below `at`.
    fn check_bounds(&self, at: &mut FieldPath) -> Result<(), FieldError>;
}

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

impl ParameterInfo {
    /// The parameter's range as the one bound type: `[min, max]` in its unit, for its reason.
    pub const fn bound(&self) -> Bound {
        Bound::new(self.min, self.max, self.unit, self.reason)
    }
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

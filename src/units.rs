//! Unit conversions between the thesis' ADAMS units (mm, kg, s, N) and SI.
//!
//! The engine works in SI throughout. ADAMS IMPACT parameters are given in
//! N/mm^e (stiffness), N·s/mm (damping) and mm (penetration depth).

/// Metres per millimetre.
pub const M_PER_MM: f64 = 1.0e-3;
/// Metres per inch.
pub const M_PER_IN: f64 = 0.0254;
/// Standard gravity, m/s² (used for "g" levels of vibration profiles).
pub const STANDARD_GRAVITY: f64 = 9.80665;
/// Milligrams per kilogram.
pub const MG_PER_KG: f64 = 1.0e6;
/// Seconds per hour.
pub const S_PER_H: f64 = 3600.0;

/// Converts an IMPACT stiffness from N/mm^e to N/m^e.
pub fn impact_stiffness_si(k_n_per_mm_e: f64, exponent: f64) -> f64 {
    k_n_per_mm_e * (1.0 / M_PER_MM).powf(exponent)
}

/// Converts a damping coefficient from N·s/mm to N·s/m.
pub fn damping_si(c_ns_per_mm: f64) -> f64 {
    c_ns_per_mm / M_PER_MM
}

/// Converts a length (or velocity) from mm (mm/s) to m (m/s).
pub fn mm(x_mm: f64) -> f64 {
    x_mm * M_PER_MM
}

/// Converts a length (or velocity) from m (m/s) back to mm (mm/s): the exact inverse of [`mm`]
/// on its values. Of the doubles `v` with `mm(v) == x_m` bit for bit, the one with the shortest
/// decimal form (the one a case file wrote), so a spec written back and read again runs with the
/// same bits and prints as it was typed. `x_m / M_PER_MM` when no double maps to `x_m`.
pub fn to_mm(x_m: f64) -> f64 {
    let guess = x_m.abs() / M_PER_MM;
    if x_m == 0.0 || !guess.is_finite() {
        return x_m / M_PER_MM;
    }
    // `mm` is odd and monotone, and a value has at most two preimages within an ulp or two of
    // the quotient: search its neighbours on the positive side.
    let bits = guess.to_bits();
    let best = (bits.saturating_sub(3)..=bits + 3)
        .map(f64::from_bits)
        .filter(|v| v.is_finite() && mm(*v).to_bits() == x_m.abs().to_bits())
        .min_by_key(|v| (v.to_string().len(), v.to_bits().abs_diff(bits)))
        .unwrap_or(guess);
    best.copysign(x_m)
}

/// Converts a length from inches to metres.
pub fn inch(x_in: f64) -> f64 {
    x_in * M_PER_IN
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn impact_stiffness_table_5_2_in_si() {
        // 1000 N/mm^2 = 1000 N / (1e-3 m)^2 = 1e9 N/m^2
        assert!((impact_stiffness_si(1000.0, 2.0) - 1.0e9).abs() < 1.0);
        // 500 N·s/mm = 5e5 N·s/m
        assert!((damping_si(500.0) - 5.0e5).abs() < 1e-6);
    }

    #[test]
    fn to_mm_is_the_exact_inverse_of_mm_and_keeps_the_typed_decimal() {
        // Table 5.2 speeds, Table 4.2's rounding, and decimals whose plain quotient
        // `mm(x) / M_PER_MM` comes back one ulp off (0.123e-3 / 1e-3 = 0.12300000000000001).
        assert_ne!(mm(0.123) / M_PER_MM, 0.123);
        for x in [
            6.4634, 12.0, 6.46, 0.123, 0.247, 1.0, 123.456, 1e-300, 5e300,
        ] {
            assert_eq!(to_mm(mm(x)), x, "{x}");
            assert_eq!(to_mm(mm(-x)), -x, "{x}");
        }
        assert_eq!(to_mm(0.0).to_bits(), 0.0f64.to_bits());
        assert_eq!(to_mm(-0.0).to_bits(), (-0.0f64).to_bits());
        assert!(to_mm(f64::NAN).is_nan());
        assert_eq!(to_mm(f64::INFINITY), f64::INFINITY);
        // Written back and read again: the same bits, for any value.
        let mut x = 0.37_f64;
        for _ in 0..10_000 {
            let m = mm(x);
            assert_eq!(mm(to_mm(m)).to_bits(), m.to_bits(), "{x}");
            x = x * 1.618_033_988_749_895 % 977.0 + 1e-3;
        }
    }
}

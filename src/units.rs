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
}

//! The thesis' parameters, written once: every default of the library that the thesis fixes
//! reads it from here (the case files in `configs/` are data and state their own values).

/// Static friction coefficient mu_s of dry anodized 7075 on 7075, eq. 4.5: Tables 4.2, 5.2
/// and 6.1.
pub const MU_STATIC: f64 = 0.1799;
/// Dynamic friction coefficient mu_d, eq. 4.5: Tables 4.2, 5.2 and 6.1.
pub const MU_DYNAMIC: f64 = 0.1660;
/// Stiction transition speed v_s, mm/s, eq. 4.5: Tables 5.2 and 6.1 (Table 4.2 rounds it to
/// 6.46).
pub const STICTION_TRANSITION_SPEED_MM_PER_S: f64 = 6.4634;
/// Friction transition speed v_d, mm/s, eq. 4.5: Tables 4.2, 5.2 and 6.1.
pub const FRICTION_TRANSITION_SPEED_MM_PER_S: f64 = 12.0;

/// ADAMS IMPACT stiffness k, N/mm^e, eq. 2.1: Tables 4.1, 5.2 and 6.2 (the default contact;
/// Table 6.2 gives the latch 1e4).
pub const IMPACT_STIFFNESS_N_PER_MM_E: f64 = 1000.0;
/// IMPACT force exponent e, eq. 2.1: Tables 4.1, 5.2 and 6.2.
pub const IMPACT_EXPONENT: f64 = 2.0;
/// IMPACT maximum damping c_max, N·s/mm, eq. 2.3: Tables 4.1, 5.2 and 6.2.
pub const IMPACT_DAMPING_NS_PER_MM: f64 = 500.0;
/// IMPACT penetration of full damping d, mm, eq. 2.3: Tables 4.1, 5.2 and 6.2.
pub const IMPACT_PENETRATION_DEPTH_MM: f64 = 0.01;

/// Density of 7075-T73, kg/m³ (thesis 4.2.1; the wear volume's mass, eq. 3.15).
pub const DENSITY_7075_KG_PER_M3: f64 = 2810.0;
/// Yield strength S_y of 7075-T73, Pa (thesis 4.2.1, eq. 2.43-2.45; the wear law's cutoff
/// 2 S_y = 870 MPa, eq. 3.11).
pub const YIELD_STRENGTH_7075_PA: f64 = 435.0e6;
/// Young's modulus E of 7075-T73, Pa (thesis 4.2.1, eq. 2.46-2.47).
pub const YOUNGS_MODULUS_7075_PA: f64 = 72.0e9;
/// Poisson's ratio nu of 7075-T73 (thesis 4.2.1, eq. 2.46-2.47).
pub const POISSON_RATIO_7075: f64 = 0.33;
/// Brinell hardness of 7075-T73, HB (thesis 4.2.1, eq. 2.43-2.45; the wear allocation by
/// inverse hardness).
pub const BRINELL_HARDNESS_7075: f64 = 135.0;

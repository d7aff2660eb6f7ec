//! Contact track samples: what every contact records at each output instant.

use serde::{Deserialize, Serialize};

/// One recorded sample of one contact track (thesis "track": one contact patch between two
/// bodies). All quantities SI, world frame unless stated.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackSample {
    /// Simulated time, s.
    pub time_s: f64,
    /// Contact (pair) index in the model's contact list.
    pub contact: u32,
    /// Track id within the contact (a new simultaneous patch between the same bodies is a new track).
    pub track: u32,
    /// Normal force magnitude, N.
    pub normal_force_n: f64,
    /// Slip velocity of body A's contact point relative to body B, tangential part, m/s (world).
    pub slip_velocity_m_s: [f64; 3],
    /// |slip velocity|, m/s.
    pub slip_speed_m_s: f64,
    /// Penetration of the deepest point, m.
    pub penetration_m: f64,
    /// Penetration rate (positive approaching), m/s.
    pub penetration_rate_m_s: f64,
    /// Contact area = overlap volume / penetration (thesis 2.5), m².
    pub area_m2: f64,
    /// Mean contact pressure N/A, Pa.
    pub pressure_pa: f64,
    /// Contact point in body A's frame, m.
    pub point_in_a_m: [f64; 3],
    /// Contact point in body B's frame, m.
    pub point_in_b_m: [f64; 3],
}

impl TrackSample {
    /// Column names for CSV export, in field order, with units.
    pub const CSV_HEADER: &'static str = "time_s,contact,track,normal_force_n,slip_vx_m_s,slip_vy_m_s,slip_vz_m_s,slip_speed_m_s,penetration_m,penetration_rate_m_s,area_m2,pressure_pa,point_a_x_m,point_a_y_m,point_a_z_m,point_b_x_m,point_b_y_m,point_b_z_m";
}

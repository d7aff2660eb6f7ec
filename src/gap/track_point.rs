//! One active contact track at one accepted step: what [`super::tracks::TrackRecord`] keeps and
//! the point-pressure binning ([`super::point_pressure`]) reads.

/// One active track at one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrackPoint {
    /// Contact index in the model.
    pub contact: u32,
    /// Track index within the contact.
    pub track: u32,
    /// Normal force, N.
    pub normal_force_n: f64,
    /// Slip speed, m/s.
    pub slip_speed_m_s: f64,
    /// Contact area, m² (thesis 2.5).
    pub area_m2: f64,
    /// Power dissipated by the IMPACT damping (normal, the impacts), W.
    pub damping_power_w: f64,
    /// Power dissipated by friction, W.
    pub friction_power_w: f64,
    /// Penetration rate of the deepest point (positive approaching), m/s.
    pub penetration_rate_m_s: f64,
    /// The track's point-pressure bins: `bins[first_bin .. first_bin + bin_count]` of the
    /// record.
    pub first_bin: u32,
    /// Number of its point-pressure bins (0 when the points were not recorded).
    pub bin_count: u32,
}

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

    /// One CSV line (no newline) in [`TrackSample::CSV_HEADER`] order. Rust's float formatting
    /// is the shortest text that parses back to the same f64, so CSV export loses nothing.
    pub fn csv_line(&self) -> String {
        let v = self.slip_velocity_m_s;
        let a = self.point_in_a_m;
        let b = self.point_in_b_m;
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            self.time_s,
            self.contact,
            self.track,
            self.normal_force_n,
            v[0],
            v[1],
            v[2],
            self.slip_speed_m_s,
            self.penetration_m,
            self.penetration_rate_m_s,
            self.area_m2,
            self.pressure_pa,
            a[0],
            a[1],
            a[2],
            b[0],
            b[1],
            b[2]
        )
    }

    /// The CSV export of `samples`: [`TrackSample::CSV_HEADER`], then one
    /// [`TrackSample::csv_line`] per sample, each line ending in `\n`. The one writer of the
    /// track CSV (`railwear run`'s `tracks.csv` and the service's `GET /v1/jobs/{id}/tracks`).
    pub fn write_csv<'a>(
        samples: impl IntoIterator<Item = &'a TrackSample>,
        mut out: impl std::io::Write,
    ) -> std::io::Result<()> {
        writeln!(out, "{}", Self::CSV_HEADER)?;
        for sample in samples {
            writeln!(out, "{}", sample.csv_line())?;
        }
        Ok(())
    }
}

/// A sample with every field set and awkward values (a subnormal, 1e300, 1/3), for tests of
/// the sample's encodings.
#[cfg(test)]
pub(crate) fn example_sample(i: usize) -> TrackSample {
    let t = i as f64 * 1e-4;
    TrackSample {
        time_s: t,
        contact: (i % 5) as u32,
        track: (i % 3) as u32,
        normal_force_n: 10.0 + (t * 50.0).sin(),
        slip_velocity_m_s: [0.01 * t, -0.02, 1.0 / 3.0],
        slip_speed_m_s: 0.5,
        penetration_m: 1e-6 * (1.0 + t),
        penetration_rate_m_s: -1e-4,
        area_m2: 2.5e-6,
        pressure_pa: 4.0e6 + t,
        point_in_a_m: [0.1, 0.2, 0.3],
        point_in_b_m: [-0.1, f64::MIN_POSITIVE, 1e300],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(i: u32) -> TrackSample {
        example_sample(i as usize)
    }

    #[test]
    fn csv_line_parses_back() {
        let s = sample(7);
        let line = s.csv_line();
        let fields: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        assert_eq!(fields.len(), TrackSample::CSV_HEADER.split(',').count());
        assert_eq!(fields[0], s.time_s);
        assert_eq!(fields[3], s.normal_force_n);
        assert_eq!(fields[17], s.point_in_b_m[2]);
    }

    #[test]
    fn write_csv_is_the_header_then_one_line_per_sample() {
        let samples = [sample(1), sample(2)];
        let mut out = Vec::new();
        TrackSample::write_csv(&samples, &mut out).unwrap();
        let expected = format!(
            "{}\n{}\n{}\n",
            TrackSample::CSV_HEADER,
            samples[0].csv_line(),
            samples[1].csv_line()
        );
        assert_eq!(String::from_utf8(out).unwrap(), expected);
        let mut empty = Vec::new();
        TrackSample::write_csv(&[], &mut empty).unwrap();
        assert_eq!(empty, format!("{}\n", TrackSample::CSV_HEADER).into_bytes());
    }
}

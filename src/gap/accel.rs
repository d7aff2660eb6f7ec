//! Accelerometer records of a physical test: the shaker input (tube / rail) or the response
//! (test item / missile), as CSV files beside the campaign manifest or inline samples in JSON.
//!
//! CSV: header `time_s,a_x_m_s2,a_y_m_s2,a_z_m_s2` (rail frame, thesis 6.2.2: x transverse, y
//! vertical, z longitudinal), one sample a row, blank lines and lines starting with `#`
//! skipped. Time must increase strictly and its step must match the declared sample rate.

use super::GapError;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// Column names of an accelerometer CSV, in order, with units.
pub const ACCEL_COLUMNS: [&str; 4] = ["time_s", "a_x_m_s2", "a_y_m_s2", "a_z_m_s2"];

/// Largest relative deviation of a time step from `1 / sample_rate_hz`: loggers time-stamp
/// from a crystal clock (ppm), and CSV export rounds times; 1 % catches a wrong declared rate
/// or a dropped sample (a 100 % step) without failing on rounding.
pub const MAX_STEP_DEVIATION: f64 = 0.01;

/// Fewest samples of a record (two give one step to check the sample rate against).
pub const MIN_SAMPLES: usize = 2;

/// Where the accelerometer sat.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AccelLocation {
    /// On the driven part (shaker table, tube, rail): the input.
    Input,
    /// On the free part (test item, missile): the response.
    Response,
}

impl AccelLocation {
    /// Lower-case name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Input => "input",
            Self::Response => "response",
        }
    }
}

/// One accelerometer record of one increment of one specimen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccelRecord {
    /// Increment the record was taken in, 1-based.
    pub increment: usize,
    /// Input or response.
    pub location: AccelLocation,
    /// Sample rate, Hz (> 0); every time step must match `1 / sample_rate_hz` within 1 %.
    pub sample_rate_hz: f64,
    /// Sensor noise, RMS, m/s² (>= 0), as the sensor's data sheet or a quiet record gives it.
    pub sensor_noise_m_s2: f64,
    /// CSV file beside the manifest (TOML form). In JSON, optional provenance only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv: Option<String>,
    /// Samples `[time_s, a_x_m_s2, a_y_m_s2, a_z_m_s2]` (JSON form; filled from `csv` when a
    /// manifest is loaded).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub samples: Vec<[f64; 4]>,
}

/// A bad sample: its index in `samples`, the column and the rule.
pub(crate) struct BadSample {
    pub index: usize,
    pub column: usize,
    pub rule: String,
}

impl AccelRecord {
    /// Checks the samples: at least [`MIN_SAMPLES`], finite values, strictly increasing time
    /// and steps matching the sample rate. The error names the sample index and column.
    pub(crate) fn check_samples(&self) -> Result<(), BadSample> {
        let bad = |index, column, rule: String| {
            Err(BadSample {
                index,
                column,
                rule,
            })
        };
        if self.samples.len() < MIN_SAMPLES {
            return bad(
                self.samples.len(),
                0,
                format!(
                    "a record needs at least {MIN_SAMPLES} samples, got {}",
                    self.samples.len()
                ),
            );
        }
        let step = 1.0 / self.sample_rate_hz;
        for (i, s) in self.samples.iter().enumerate() {
            if let Some(j) = s.iter().position(|x| !x.is_finite()) {
                return bad(i, j, format!("must be a finite number, got {}", s[j]));
            }
            if i == 0 {
                continue;
            }
            let dt = s[0] - self.samples[i - 1][0];
            if !(dt > 0.0) {
                return bad(
                    i,
                    0,
                    format!(
                        "time must increase strictly: {} s follows {} s",
                        s[0],
                        self.samples[i - 1][0]
                    ),
                );
            }
            if (dt / step - 1.0).abs() > MAX_STEP_DEVIATION {
                return bad(
                    i,
                    0,
                    format!(
                        "time step {dt} s does not match sample_rate_hz {} (step {step} s, \
                         within 1 %)",
                        self.sample_rate_hz
                    ),
                );
            }
        }
        Ok(())
    }

    /// Mean square of each axis over the record, (m/s²)².
    pub fn mean_square_m2_s4(&self) -> [f64; 3] {
        let n = self.samples.len().max(1) as f64;
        let mut out = [0.0; 3];
        for s in &self.samples {
            for k in 0..3 {
                out[k] += s[k + 1] * s[k + 1] / n;
            }
        }
        out
    }
}

/// Parses accelerometer CSV text. Returns the samples and, for each, its 1-based row number;
/// errors name `field`, `file`, the row and the column.
pub(crate) fn parse_csv(
    text: &str,
    field: &str,
    file: &str,
) -> Result<(Vec<[f64; 4]>, Vec<usize>), GapError> {
    let err = |row: usize, column: usize, rule: String| GapError::Csv {
        field: field.to_string(),
        file: file.to_string(),
        row,
        column: ACCEL_COLUMNS[column.min(3)].to_string(),
        rule,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_start_matches('\u{feff}').trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((header_row, header)) = lines.next() else {
        return Err(err(
            1,
            0,
            format!(
                "file is empty; expected the header `{}`",
                ACCEL_COLUMNS.join(",")
            ),
        ));
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    if names != ACCEL_COLUMNS {
        let column = names
            .iter()
            .zip(ACCEL_COLUMNS)
            .position(|(a, b)| *a != b)
            .unwrap_or(names.len().min(3));
        return Err(err(
            header_row,
            column,
            format!(
                "header must be `{}`, got `{header}`",
                ACCEL_COLUMNS.join(",")
            ),
        ));
    }
    let mut samples = Vec::new();
    let mut rows = Vec::new();
    for (row, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != 4 {
            return Err(err(
                row,
                cells.len().min(3),
                format!("expected 4 comma-separated values, got {}", cells.len()),
            ));
        }
        let mut sample = [0.0; 4];
        for (j, cell) in cells.iter().enumerate() {
            sample[j] = cell
                .parse()
                .map_err(|_| err(row, j, format!("`{cell}` is not a number")))?;
        }
        samples.push(sample);
        rows.push(row);
    }
    Ok((samples, rows))
}

/// CSV text of samples, with the header; numbers printed so they read back bit for bit.
pub fn to_csv(samples: &[[f64; 4]]) -> String {
    let mut out = String::with_capacity(samples.len() * 64);
    out.push_str(&ACCEL_COLUMNS.join(","));
    out.push('\n');
    for s in samples {
        let _ = writeln!(out, "{:?},{:?},{:?},{:?}", s[0], s[1], s[2], s[3]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(samples: Vec<[f64; 4]>) -> AccelRecord {
        AccelRecord {
            increment: 1,
            location: AccelLocation::Input,
            sample_rate_hz: 1000.0,
            sensor_noise_m_s2: 0.0,
            csv: None,
            samples,
        }
    }

    #[test]
    fn csv_round_trips_bit_for_bit() {
        let samples = vec![[0.0, 0.1, -2.5e-7, 3.0], [0.001, 1.0 / 3.0, 0.0, -9.80665]];
        let (back, rows) = parse_csv(&to_csv(&samples), "f", "x.csv").unwrap();
        assert_eq!(back, samples);
        assert_eq!(rows, vec![2, 3]);
    }

    #[test]
    fn step_must_match_the_rate() {
        let ok = record(vec![
            [0.0; 4],
            [0.001, 0.0, 0.0, 0.0],
            [0.002, 0.0, 0.0, 0.0],
        ]);
        assert!(ok.check_samples().is_ok());
        // A dropped sample doubles the step at index 2.
        let gap = record(vec![
            [0.0; 4],
            [0.001, 0.0, 0.0, 0.0],
            [0.003, 0.0, 0.0, 0.0],
        ]);
        let bad = gap.check_samples().unwrap_err();
        assert_eq!((bad.index, bad.column), (2, 0));
        assert!(bad.rule.contains("sample_rate_hz"), "{}", bad.rule);
    }
}

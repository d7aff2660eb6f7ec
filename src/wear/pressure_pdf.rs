//! Log-binned histogram of contact pressure, weighted by contact time and by friction work
//! N·|v_slip| (Figure 6.65 plots the probability density of contact pressure per contact).

use super::WearError;
use crate::field_error::FieldError;
use serde::{Deserialize, Serialize};

/// Histogram over log-spaced pressure bins plus under- and overflow tallies.
/// The bins never change after construction, so adding is allocation-free.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PressureHistogram {
    /// Lower edge of the first bin, Pa.
    pub min_pressure_pa: f64,
    /// Number of bins per decade of pressure.
    pub bins_per_decade: u32,
    /// Contact time per bin, s.
    pub time_s: Vec<f64>,
    /// Friction work N·|v_slip|·dt per bin, J.
    pub work_j: Vec<f64>,
    /// Contact time at pressures below `min_pressure_pa` (including sigma = 0 with N > 0), s.
    pub underflow_time_s: f64,
    /// Friction work below `min_pressure_pa`, J.
    pub underflow_work_j: f64,
    /// Contact time above the last edge (including infinite pressure, zero area), s.
    pub overflow_time_s: f64,
    /// Friction work above the last edge, J.
    pub overflow_work_j: f64,
}

impl Default for PressureHistogram {
    /// 1 kPa to 100 GPa, 10 bins per decade (80 bins): wide enough for a rattling cube's spikes.
    fn default() -> Self {
        Self::new(1.0e3, 1.0e11, 10).unwrap_or_else(|_| unreachable!("constant bin spec is valid"))
    }
}

impl PressureHistogram {
    /// Bins from `min_pressure_pa` to `max_pressure_pa` (rounded up to whole bins).
    pub fn new(
        min_pressure_pa: f64,
        max_pressure_pa: f64,
        bins_per_decade: u32,
    ) -> Result<Self, WearError> {
        FieldError::positive("min_pressure_pa", min_pressure_pa)?;
        if !(max_pressure_pa.is_finite() && max_pressure_pa > min_pressure_pa) {
            return Err(
                FieldError::new("max_pressure_pa", "must be finite and > min_pressure_pa").into(),
            );
        }
        if bins_per_decade == 0 || bins_per_decade > 1000 {
            return Err(FieldError::new("bins_per_decade", "must be in 1..=1000").into());
        }
        let decades = (max_pressure_pa / min_pressure_pa).log10();
        let n = (decades * bins_per_decade as f64 - 1e-9).ceil().max(1.0) as usize;
        if n > 100_000 {
            return Err(FieldError::new("max_pressure_pa", "gives more than 100000 bins").into());
        }
        Ok(Self {
            min_pressure_pa,
            bins_per_decade,
            time_s: vec![0.0; n],
            work_j: vec![0.0; n],
            underflow_time_s: 0.0,
            underflow_work_j: 0.0,
            overflow_time_s: 0.0,
            overflow_work_j: 0.0,
        })
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// True when there are no bins (never, after [`PressureHistogram::new`]).
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// Edge `i` (0..=len), Pa.
    pub fn edge_pa(&self, i: usize) -> f64 {
        self.min_pressure_pa * 10f64.powf(i as f64 / self.bins_per_decade as f64)
    }

    /// Geometric centre of bin `i`, Pa.
    pub fn center_pa(&self, i: usize) -> f64 {
        (self.edge_pa(i) * self.edge_pa(i + 1)).sqrt()
    }

    /// Adds `time_s` of contact and `work_j` of friction work at pressure `pressure_pa`.
    #[inline]
    pub fn add(&mut self, pressure_pa: f64, time_s: f64, work_j: f64) {
        if pressure_pa.is_nan() || pressure_pa < self.min_pressure_pa {
            self.underflow_time_s += time_s;
            self.underflow_work_j += work_j;
            return;
        }
        let pos = (pressure_pa / self.min_pressure_pa).log10() * self.bins_per_decade as f64;
        if pos.is_finite() && (pos as usize) < self.time_s.len() {
            let i = pos as usize;
            self.time_s[i] += time_s;
            self.work_j[i] += work_j;
        } else {
            self.overflow_time_s += time_s;
            self.overflow_work_j += work_j;
        }
    }

    /// Total contact time including under- and overflow, s.
    pub fn total_time_s(&self) -> f64 {
        self.time_s.iter().sum::<f64>() + self.underflow_time_s + self.overflow_time_s
    }

    /// Total friction work including under- and overflow, J.
    pub fn total_work_j(&self) -> f64 {
        self.work_j.iter().sum::<f64>() + self.underflow_work_j + self.overflow_work_j
    }

    /// Adds another histogram with the same bins (the tracks of one contact).
    pub fn merge(&mut self, other: &PressureHistogram) -> Result<(), WearError> {
        if self.min_pressure_pa != other.min_pressure_pa
            || self.bins_per_decade != other.bins_per_decade
            || self.len() != other.len()
        {
            return Err(FieldError::new("pressure_histogram", "bins must match to merge").into());
        }
        for (a, b) in self.time_s.iter_mut().zip(&other.time_s) {
            *a += b;
        }
        for (a, b) in self.work_j.iter_mut().zip(&other.work_j) {
            *a += b;
        }
        self.underflow_time_s += other.underflow_time_s;
        self.underflow_work_j += other.underflow_work_j;
        self.overflow_time_s += other.overflow_time_s;
        self.overflow_work_j += other.overflow_work_j;
        Ok(())
    }

    /// Probability density per Pa of contact pressure, time-weighted: `(centre_pa, density)`
    /// per bin, normalised by the total contact time (so the out-of-range mass is not lost).
    pub fn time_density_per_pa(&self) -> Vec<(f64, f64)> {
        self.density(&self.time_s, self.total_time_s())
    }

    /// Probability density per Pa, weighted by friction work N·|v_slip| (where wear happens).
    pub fn work_density_per_pa(&self) -> Vec<(f64, f64)> {
        self.density(&self.work_j, self.total_work_j())
    }

    fn density(&self, weights: &[f64], total: f64) -> Vec<(f64, f64)> {
        weights
            .iter()
            .enumerate()
            .map(|(i, w)| {
                let width = self.edge_pa(i + 1) - self.edge_pa(i);
                let d = if total > 0.0 {
                    w / (total * width)
                } else {
                    0.0
                };
                (self.center_pa(i), d)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_edges_and_overflow() {
        let mut h = PressureHistogram::new(1.0, 1000.0, 1).unwrap();
        assert_eq!(h.len(), 3);
        assert!((h.edge_pa(2) - 100.0).abs() < 1e-9);
        h.add(5.0, 1.0, 2.0); // bin 0
        h.add(50.0, 1.0, 0.0); // bin 1
        h.add(0.5, 3.0, 0.0); // underflow
        h.add(f64::INFINITY, 4.0, 1.0); // overflow
        assert_eq!(h.time_s, vec![1.0, 1.0, 0.0]);
        assert_eq!((h.underflow_time_s, h.overflow_time_s), (3.0, 4.0));
        assert_eq!(h.total_time_s(), 9.0);
        assert_eq!(h.total_work_j(), 3.0);
    }

    #[test]
    fn density_integrates_to_the_in_range_share() {
        let mut h = PressureHistogram::default();
        h.add(2.0e6, 3.0, 1.0);
        h.add(7.0e8, 1.0, 1.0);
        h.add(1.0, 1.0, 0.0);
        let integral: f64 = h
            .time_density_per_pa()
            .iter()
            .enumerate()
            .map(|(i, (_, d))| d * (h.edge_pa(i + 1) - h.edge_pa(i)))
            .sum();
        assert!((integral - 0.8).abs() < 1e-12, "{integral}");
    }
}

//! Predictions from the tables: an effect set at any magnitudes (interpolated log-linearly
//! between grid points, exact pair tables and joint points where they exist, the product of
//! ratios otherwise), and the tables of one effect or pair.

use super::{Emulator, TestPredictions};

impl Emulator {
    /// Predictions with the effects `(table index, magnitude)`: one effect from its table;
    /// two or more as the nominal times each one's ratio to the nominal.
    pub fn predict(&self, effects: &[(usize, f64)]) -> TestPredictions {
        match effects {
            [] => self.nominal.clone(),
            [(e, m)] => self.effects[*e].at(*m),
            // A member at 0 is the other alone, exactly.
            [(_, z), one] | [one, (_, z)] if *z == 0.0 => self.effects[one.0].at(one.1),
            [(a, ma), (b, mb)] if self.pair(*a, *b).is_some() => {
                let p = &self.pairs[self.pair(*a, *b).unwrap_or_default()];
                if p.dynamics == *a {
                    p.at(*ma, *mb)
                } else {
                    p.at(*mb, *ma)
                }
            }
            [(a, ma), (b, mb)] if self.has_joint(*a, *b) => self.interacting(*a, *ma, *b, *mb),
            many => self.product(many),
        }
    }

    /// Magnitude `m` of table `t` over the table's bound on its side of 0.
    pub fn unit(&self, t: usize, m: f64) -> f64 {
        m / self.effects[t].bound_for(m).abs().max(1e-300)
    }

    /// Whether tables `a` and `b` were simulated together anywhere.
    fn has_joint(&self, a: usize, b: usize) -> bool {
        self.joints
            .iter()
            .any(|j| j.tables == [a, b] || j.tables == [b, a])
    }

    /// Tables `a` at `ma` and `b` at `mb` together: the product of their ratios times an
    /// interaction the joint simulations measure (docs/results/diagnosis.md, "Two dynamics effects
    /// together"). With `u`, `v` each magnitude over its bound, the interaction of a quantity
    /// is `exp(u v h(u, v))` (a product that is 0 at the joint points: `+ u v h`), where
    /// `h_i = ln(joint_i / product_i) / (u_i v_i)` at each joint point is interpolated by
    /// inverse squared distance in `(u, v)`. So it is exact at every joint point, vanishes
    /// where either member is off (the product is exact there), and is smooth in both
    /// magnitudes: a fit moving between joint points sees no jump.
    fn interacting(&self, a: usize, ma: f64, b: usize, mb: f64) -> TestPredictions {
        let (u, v) = (self.unit(a, ma), self.unit(b, mb));
        // (u_i, v_i, joint, product) at each joint point of the two tables, in (a, b) order.
        let points: Vec<(f64, f64, &TestPredictions, TestPredictions)> = self
            .joints
            .iter()
            .filter_map(|j| {
                let (x, y) = if j.tables == [a, b] {
                    (j.magnitudes[0], j.magnitudes[1])
                } else if j.tables == [b, a] {
                    (j.magnitudes[1], j.magnitudes[0])
                } else {
                    return None;
                };
                let (ui, vi) = (self.unit(a, x), self.unit(b, y));
                (ui * vi != 0.0).then(|| (ui, vi, &j.predictions, self.product(&[(a, x), (b, y)])))
            })
            .collect();
        let mut out = self.product(&[(a, ma), (b, mb)]);
        // Weights: one at a joint point (exact there), inverse squared distance otherwise.
        let d2: Vec<f64> = points
            .iter()
            .map(|(ui, vi, _, _)| (u - ui).powi(2) + (v - vi).powi(2))
            .collect();
        let weights: Vec<f64> = match d2.iter().position(|d| *d < 1e-24) {
            Some(k) => (0..d2.len()).map(|i| f64::from(u8::from(i == k))).collect(),
            None => d2.iter().map(|d| 1.0 / d).collect(),
        };
        let total: f64 = weights.iter().sum();
        if points.is_empty() || !(total > 0.0) {
            return out;
        }
        let uv = u * v;
        for (ti, t) in out.iter_mut().enumerate() {
            for (k, q) in t.iter_mut().enumerate() {
                let at = |i: usize| (&points[i].2[ti][k], &points[i].3[ti][k]);
                // Multiplicative where every joint point and its product are positive.
                let mut h_log = q.zip(q, |_, _| 0.0);
                let mut h_add = h_log.clone();
                let mut positive = q.zip(q, |x, _| if x > 0.0 { 1.0 } else { 0.0 });
                for (i, (ui, vi, _, _)) in points.iter().enumerate() {
                    let (joint, base) = at(i);
                    let w = weights[i] / total / (ui * vi);
                    let log = joint.zip(base, |j, p| {
                        if j > 0.0 && p > 0.0 {
                            (j / p).ln()
                        } else {
                            f64::NAN
                        }
                    });
                    positive = positive.zip(&log, |s, l| if l.is_nan() { 0.0 } else { s });
                    h_log = h_log.zip(&log, |h, l| if l.is_nan() { h } else { h + w * l });
                    h_add = h_add.zip(&joint.zip(base, |j, p| j - p), |h, d| h + w * d);
                }
                let scaled = q.zip(&h_log, |x, h| x * (uv * h).exp());
                let added = q.zip(&h_add, |x, h| x + uv * h);
                let mixed = scaled.zip(&positive, |x, s| if s > 0.0 { x } else { f64::NAN });
                *q = mixed.zip(&added, |x, a| if x.is_nan() { a } else { x });
            }
        }
        out
    }

    /// The nominal times each effect's ratio to the nominal.
    fn product(&self, effects: &[(usize, f64)]) -> TestPredictions {
        let mut out = self.nominal.clone();
        for (e, m) in effects {
            let p = self.effects[*e].at(*m);
            for (ti, t) in out.iter_mut().enumerate() {
                for (k, q) in t.iter_mut().enumerate() {
                    let nom = &self.nominal[ti][k];
                    let ratio = nom.zip(&p[ti][k], |n, x| if n > 0.0 { x / n } else { f64::NAN });
                    let delta = nom.zip(&p[ti][k], |n, x| x - n);
                    *q = q.zip(&ratio, |a, r| a * r);
                    // Where the nominal is 0, add the effect's own amount.
                    let fixed = q.zip(&delta, |a, d| if a.is_nan() { d } else { a });
                    *q = fixed;
                }
            }
        }
        out
    }

    /// Whether a joint point of tables `a` and `b` (either order) is held within relative
    /// distance `tolerance` of magnitudes `ma` and `mb` (0: at exactly them).
    pub fn joint_near(&self, [(a, ma), (b, mb)]: [(usize, f64); 2], tolerance: f64) -> bool {
        let near = |x: f64, y: f64| (x - y).abs() <= tolerance * y.abs();
        self.joints.iter().any(|j| {
            (j.tables == [a, b] && near(j.magnitudes[0], ma) && near(j.magnitudes[1], mb))
                || (j.tables == [b, a] && near(j.magnitudes[1], ma) && near(j.magnitudes[0], mb))
        })
    }

    /// Every table of the effect of table `t` (its library defaults and its variants), in
    /// table order; when a measurement of the effect's secondary values is held and some
    /// table agrees with it, only the tables that agree (`measured`).
    pub fn family(&self, t: usize) -> Vec<usize> {
        let name = self.effects[t].info.name;
        let all: Vec<usize> = (0..self.effects.len())
            .filter(|&i| self.effects[i].info.name == name)
            .collect();
        let agreeing: Vec<usize> = all
            .iter()
            .copied()
            .filter(|&i| self.agrees_with_measurements(i))
            .collect();
        if agreeing.is_empty() {
            all
        } else {
            agreeing
        }
    }

    /// Index of the exact pair table of tables `a` and `b` (either order), if built.
    pub fn pair(&self, a: usize, b: usize) -> Option<usize> {
        self.pairs
            .iter()
            .position(|p| (p.dynamics, p.wear) == (a, b) || (p.dynamics, p.wear) == (b, a))
    }
}

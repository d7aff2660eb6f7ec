//! Pairs of effects: which pairs to try given the singles, the table combinations a pair may
//! take (its members' secondary values chosen with the other member on), and the fit of two
//! tables' magnitudes (docs/results/diagnosis.md, "Exact pairs", "A pair's secondary values").

use super::candidate::Candidate;
use super::fit_problem::{unless_beaten, Fit, FitProblem, Model};
use crate::gap::effects::Acts;

impl FitProblem<'_> {
    /// Best magnitudes of tables `a` and `b` together on the groups `mask` keeps: every
    /// magnitude of each alone (the singles' own candidates, so a pair never fits the training
    /// data worse than either member), then both over the tables' points, refined five-fold
    /// around the best; both are taken only when they beat the better member alone by more
    /// than [`PROFILE_95`](super::PROFILE_95).
    pub(super) fn fit_pair_tables(&self, a: usize, b: usize, mask: &dyn Fn(usize) -> bool) -> Fit {
        let mut member = (vec![(a, 0.0), (b, 0.0)], self.nll_of(&[], mask));
        let consider = |best: &mut Fit, x: f64, y: f64| {
            let spec = vec![(a, x), (b, y)];
            let nll = self.nll_of(&spec, mask);
            if nll < best.1 {
                *best = (spec, nll);
            }
        };
        for x in self.candidates(a) {
            consider(&mut member, x, 0.0);
        }
        for y in self.candidates(b) {
            consider(&mut member, 0.0, y);
        }
        let mut joint = (Vec::new(), f64::INFINITY);
        let (ma, mb) = (
            &self.emulator.effects[a].magnitudes,
            &self.emulator.effects[b].magnitudes,
        );
        for &x in ma {
            for &y in mb {
                consider(&mut joint, x, y);
            }
        }
        if let [(_, x0), (_, y0)] = joint.0[..] {
            for x in self.candidates_near(a, x0) {
                for y in self.candidates_near(b, y0) {
                    consider(&mut joint, x, y);
                }
            }
        }
        unless_beaten(member, std::iter::once(joint))
    }

    /// Other table combinations of the effects of tables `a` and `b` a pair may take (their
    /// secondary values profiled with the other member on). Two dynamics effects: every two
    /// of their tables (the product of their ratios, corrected by the joint simulations the
    /// refinement adds where the fits land). A dynamics effect with a wear law: one member's
    /// variant with the other's table, where an exact pair table holds them.
    pub(super) fn pair_combinations(&self, a: usize, b: usize) -> Vec<(usize, usize)> {
        let e = &self.emulator;
        let (fa, fb) = (self.family_of(a), self.family_of(b));
        let mut out = Vec::new();
        for &ta in &self.families[fa] {
            for &tb in &self.families[fb] {
                let take = match (e.effects[ta].info.acts, e.effects[tb].info.acts) {
                    (Acts::Dynamics, Acts::Dynamics) => true,
                    (Acts::WearLaw, Acts::WearLaw) => false,
                    _ => (ta == a) != (tb == b) && e.pair(ta, tb).is_some(),
                };
                if take && (ta, tb) != (a, b) {
                    out.push((ta, tb));
                }
            }
        }
        out
    }

    /// The pairs to try given the singles: every two of the four best singles that beat the
    /// nominal held out, each on the table its full-data fit chose, in library order.
    pub(super) fn pair_models(&self, singles: &[Candidate], nominal: &Candidate) -> Vec<Model> {
        let mut order: Vec<usize> = (0..singles.len()).collect();
        order.sort_by(|a, b| singles[*b].held_ll().total_cmp(&singles[*a].held_ll()));
        let top: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&i| singles[i].held_ll() > nominal.held_ll())
            .take(4)
            .collect();
        let mut out = Vec::new();
        let mut push = |ta: usize, tb: usize| {
            let (fa, fb) = (self.family_of(ta), self.family_of(tb));
            let m = if fa < fb {
                Model::Pair(ta, tb)
            } else {
                Model::Pair(tb, ta)
            };
            if fa != fb && !out.contains(&m) {
                out.push(m);
            }
        };
        for (ai, &a) in top.iter().enumerate() {
            for &b in &top[ai + 1..] {
                push(singles[a].table(), singles[b].table());
            }
        }
        // A wear law may act only on the tracks a dynamics effect brings (wear above the
        // cutoff under a cross-axis drive), invisible alone on the nominal tracks: the two best
        // dynamics singles are paired with every wear-law effect.
        let dynamics = top
            .iter()
            .filter(|&&i| self.emulator.effects[singles[i].table()].info.acts == Acts::Dynamics)
            .take(2);
        for &d in dynamics {
            for (f, c) in singles.iter().enumerate() {
                if self.emulator.effects[self.families[f][0]].info.acts == Acts::WearLaw {
                    push(singles[d].table(), c.table());
                }
            }
        }
        out
    }
}

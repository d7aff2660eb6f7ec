//! Step 3 of the refinement, the pairs (docs/results/diagnosis.md, "Exact pairs", "A pair's
//! secondary values", "A pair's landing"): exact dynamics + wear-law pair tables and their
//! members' variants made exact together, the tables of two dynamics effects simulated
//! together at the pair's fit, and a dynamics partner of the leading dynamics single bisected
//! beside it and followed to where its fits land.

use super::candidate::{requests_of, Candidate};
use super::fit_problem::{FitProblem, Model};
use super::options::Simulating;
use super::secondary_values::{midpoints_beside, profile_values};
use super::verdict::{singles_if_gap, singles_unexplained};
use crate::gap::diagnose::emulator::Emulator;
use crate::gap::effects::Acts;
use crate::gap::GapError;
use std::collections::BTreeMap;

/// Rounds of refinement of the pairs' dynamics members.
const PAIR_ROUNDS: usize = 2;

/// Step 3: when no single effect explains cleanly, the pairs of the best singles: each
/// dynamics + wear-law pair made exact, and the dynamics members of every pair refined at
/// the magnitudes the pair's fits land on (the exact pairs follow their refined tables).
pub(super) fn exact_pairs(sim: Simulating, emulator: &mut Emulator) -> Result<(), GapError> {
    let (campaign, options, configs_dir, control, cache) = sim.parts();
    for round in 0..=PAIR_ROUNDS {
        let (models, requests) = {
            let problem = FitProblem::new(campaign, emulator, options);
            // Pairs are tried beside a single that explains only partly too.
            let Some((nominal, singles)) =
                singles_unexplained(campaign, &problem, options, emulator)
            else {
                return Ok(());
            };
            let models = problem.pair_models(&singles, &nominal);
            let mut requests: Vec<(usize, f64)> = Vec::new();
            let mut joints: Vec<[(usize, f64); 2]> = Vec::new();
            if round > 0 {
                for m in &models {
                    let c = problem.evaluate(*m, options.alpha);
                    requests.extend(requests_of(emulator, &c));
                    // Two dynamics effects: simulated together where the fits land.
                    for s in std::iter::once(&c.spec).chain(c.fold_specs.iter()) {
                        if let [a, b] = s[..] {
                            let both =
                                emulator.effects[a.0].simulated && emulator.effects[b.0].simulated;
                            if both && a.1 != 0.0 && b.1 != 0.0 && !joints.contains(&[a, b]) {
                                joints.push([a, b]);
                            }
                        }
                    }
                }
            }
            (models, (requests, joints))
        };
        let (requests, joints) = requests;
        if round == 0 {
            for m in &models {
                if let Model::Pair(a, b) = *m {
                    let (acts_a, acts_b) =
                        (emulator.effects[a].info.acts, emulator.effects[b].info.acts);
                    let pair = match (acts_a, acts_b) {
                        (Acts::Dynamics, Acts::WearLaw) => Some((a, b)),
                        (Acts::WearLaw, Acts::Dynamics) => Some((b, a)),
                        _ => None,
                    };
                    if let Some((d, w)) = pair {
                        if emulator.pair(d, w).is_none() {
                            emulator.add_pair(campaign, configs_dir, d, w, control, cache)?;
                        }
                    }
                }
            }
            pair_variants(sim, emulator)?;
            continue;
        }
        let mut added =
            emulator.refine(campaign, configs_dir, &requests, control, cache, &|_, _| {})?;
        for [a, b] in joints {
            if emulator.add_joint(campaign, configs_dir, a, b, control, cache)? {
                added += 1;
            }
        }
        if added == 0 {
            break;
        }
    }
    Ok(())
}

/// Dynamics + wear-law pairs whose members' variants get exact pair tables.
const PAIR_VARIANT_CONTENDERS: usize = 2;

/// The secondary values of a dynamics + wear-law pair's members profiled together: a
/// single's profile chose each member's variant without the other member, which may have
/// pulled it (a pressure threshold fitted to the nominal tracks, not to a cross-axis drive's).
/// For the [`PAIR_VARIANT_CONTENDERS`] best such pairs by held-out likelihood that beat the
/// nominal, each member's variant tables get an exact pair table with the other member's
/// (the wear law on the dynamics effect's own windows); the pair's fit then chooses among
/// them (`FitProblem::pair_combinations`). For the as many best pairs of two dynamics
/// effects, each member's tables are simulated with the other at the pair's fit (a member
/// the fit left at 0 at its single's fit): the product of their ratios may hide what one
/// adds beside the other, and a joint point corrects it; the refinement rounds then simulate
/// the chosen two together where the fits land.
fn pair_variants(sim: Simulating, emulator: &mut Emulator) -> Result<(), GapError> {
    let (campaign, options, configs_dir, control, cache) = sim.parts();
    // (dynamics table, wear-law table) of each mixed pair to profile, and (table,
    // magnitude) twice for each pair of dynamics effects.
    type Contenders = (
        Vec<(usize, usize)>,
        Vec<[(usize, f64); 2]>,
        Vec<[(usize, f64); 2]>,
    );
    let (contenders, dynamics, beside_leader): Contenders = {
        let problem = FitProblem::new(campaign, emulator, options);
        let Some((nominal, singles)) = singles_if_gap(campaign, &problem, options) else {
            return Ok(());
        };
        let mut pairs: Vec<(bool, Candidate)> = problem
            .pair_models(&singles, &nominal)
            .into_iter()
            .filter_map(|m| match m {
                Model::Pair(a, b) => {
                    let acts = (emulator.effects[a].info.acts, emulator.effects[b].info.acts);
                    (acts != (Acts::WearLaw, Acts::WearLaw)).then_some((acts.0 == acts.1, m))
                }
                _ => None,
            })
            .map(|(both, m)| (both, problem.evaluate(m, options.alpha)))
            .filter(|(_, c)| c.held_ll() > nominal.held_ll())
            .collect();
        pairs.sort_by(|a, b| b.1.held_ll().total_cmp(&a.1.held_ll()));
        let mixed = pairs
            .iter()
            .filter(|(both, _)| !both)
            .take(PAIR_VARIANT_CONTENDERS)
            .filter_map(|(_, c)| match c.spec[..] {
                [(a, _), (b, _)] if emulator.effects[a].info.acts == Acts::Dynamics => Some((a, b)),
                [(a, _), (b, _)] => Some((b, a)),
                _ => None,
            })
            .collect();
        // A member the pair's fit left at 0 is put at its single's fit: the product of the
        // two ratios may hide what the member adds beside the other.
        let single_magnitude = |t: usize| {
            singles[problem.family_of(t)]
                .spec
                .first()
                .map_or(0.0, |s| s.1)
        };
        let dynamics = pairs
            .iter()
            .filter(|(both, _)| *both)
            .take(PAIR_VARIANT_CONTENDERS)
            .filter_map(|(_, c)| match c.spec[..] {
                [(a, ma), (b, mb)] => Some([
                    (a, if ma != 0.0 { ma } else { single_magnitude(a) }),
                    (b, if mb != 0.0 { mb } else { single_magnitude(b) }),
                ]),
                _ => None,
            })
            .collect();
        // The leading dynamics single, and every other dynamics effect a pair puts beside
        // it: both at the pair's fit (each at its single's when the pair left it at 0).
        let leader = pairs
            .iter()
            .flat_map(|(_, c)| c.spec.iter().map(|s| problem.family_of(s.0)))
            .filter(|&f| emulator.effects[problem.families[f][0]].info.acts == Acts::Dynamics)
            .max_by(|x, y| singles[*x].held_ll().total_cmp(&singles[*y].held_ll()))
            .and_then(|f| singles[f].spec.first().copied());
        let mut beside_leader: Vec<[(usize, f64); 2]> = Vec::new();
        if let Some(l) = leader {
            let lf = problem.family_of(l.0);
            for (both, c) in &pairs {
                let [x, y] = match c.spec[..] {
                    [x, y] if *both => [x, y],
                    _ => continue,
                };
                let (at, (t, m)) =
                    match (problem.family_of(x.0) == lf, problem.family_of(y.0) == lf) {
                        (true, false) => (x, y),
                        (false, true) => (y, x),
                        _ => continue,
                    };
                let m = if m != 0.0 { m } else { single_magnitude(t) };
                // The leader where this pair's fit puts it: a single pushed to its bound
                // by what its partner carries is no place to bisect the partner.
                let leader = if at.1 != 0.0 { at } else { l };
                if !beside_leader.iter().any(|p| p[1].0 == t) {
                    beside_leader.push([leader, (t, m)]);
                }
            }
        }
        (mixed, dynamics, beside_leader)
    };
    // Two dynamics effects: each member's tables simulated with the other at the pair's fit.
    for [(a, ma), (b, mb)] in dynamics {
        for a2 in emulator.family(a) {
            emulator.add_joint(campaign, configs_dir, (a2, ma), (b, mb), control, cache)?;
        }
        for b2 in emulator.family(b) {
            emulator.add_joint(campaign, configs_dir, (a, ma), (b2, mb), control, cache)?;
        }
    }
    // Each partner of the leading dynamics effect: its secondary value bisected beside it.
    for [leader, (partner, m)] in beside_leader {
        if m != 0.0 && leader.1 != 0.0 {
            let landed = bisect_beside(sim, emulator, (partner, m), leader)?;
            // The leader's magnitude where the partner's best table lands beside it, far from
            // where the bisection put it (the product of the two ratios misplaced the pair):
            // bisected again there.
            if let Some([(t, at), (o, ao)]) = landed {
                if (ao / leader.1).abs().ln().abs() > LEADER_MOVE.ln() {
                    bisect_beside(sim, emulator, (t, at), (o, ao))?;
                }
            }
        }
    }
    for (d, w) in contenders {
        // Each member's own table is paired already (round 0 of `exact_pairs`).
        for w2 in emulator.family(w) {
            if emulator.pair(d, w2).is_none() {
                emulator.add_pair(campaign, configs_dir, d, w2, control, cache)?;
            }
        }
        for d2 in emulator.family(d) {
            if emulator.pair(d2, w).is_none() {
                emulator.add_pair(campaign, configs_dir, d2, w, control, cache)?;
            }
        }
    }
    Ok(())
}

/// Bisection passes of a dynamics pair member's secondary value with the other member on.
const PAIR_BISECTIONS: usize = 3;
/// Factor by which the leader's magnitude where a bisected partner lands may differ from
/// where it was bisected before the partner is bisected again there.
const LEADER_MOVE: f64 = 2.0;

/// The secondary value of dynamics table `member`'s effect (one secondary parameter) chosen
/// with table `other` on at its magnitude: a single's profile chose it without the other,
/// and the other may move it (a cross-axis drive adds sliding, so a friction drift over slip
/// runs its course over less test time: its slip scale fitted alone is not the pair's).
/// Every table of the member's family (seeded with the profile's five values when it holds
/// fewer than three, each simulated at `m`) is simulated beside `other` and fitted with it;
/// [`PAIR_BISECTIONS`] times, variants midway between the best value and its neighbours are
/// added, each simulated alone and beside `other` where the best table's pair fit lands (two
/// simulations per value: the pair's fit moves the member's magnitude along the variant's
/// table from 0 to there, and the joint point makes it exact there). Nothing is done when
/// the effect has no single secondary parameter. Then [`land_beside`]; returns where the
/// member's best table lands beside `other` (None when nothing was bisected or no fit puts
/// both on).
fn bisect_beside(
    sim: Simulating,
    emulator: &mut Emulator,
    (member, m): (usize, f64),
    (other, mo): (usize, f64),
) -> Result<Option<Landing>, GapError> {
    let (campaign, options, configs_dir, control, cache) = sim.parts();
    let info = emulator.effects[member].info;
    let [_, p] = info.parameters else {
        return Ok(None);
    };
    let Some(default_table) = emulator
        .family(member)
        .into_iter()
        .find(|&t| emulator.effects[t].parameters.is_empty())
    else {
        return Ok(None);
    };
    let add = |emulator: &mut Emulator, v: f64, grid: &[f64], at: f64| -> Result<(), GapError> {
        let t = emulator.add_variant(
            campaign,
            configs_dir,
            default_table,
            BTreeMap::from([(p.name.to_string(), v)]),
            grid,
            control,
            cache,
        )?;
        emulator.add_joint(campaign, configs_dir, (t, at), (other, mo), control, cache)?;
        Ok(())
    };
    if emulator.family(member).len() < 3 {
        let grid = [m];
        for v in profile_values(p, 5) {
            if v != p.default {
                add(emulator, v, &grid, m)?;
            }
        }
    }
    // Every table of the family simulated beside `other` once, so none is judged on the
    // product of ratios alone.
    for t in emulator.family(member) {
        emulator.add_joint(campaign, configs_dir, (t, m), (other, mo), control, cache)?;
    }
    // Each table's value and its pair fit beside `other` (full data), by value.
    let tried = |emulator: &Emulator| -> Vec<(f64, usize, f64, f64)> {
        let problem = FitProblem::new(campaign, emulator, options);
        let mut tried: Vec<(f64, usize, f64, f64)> = emulator
            .family(member)
            .into_iter()
            .map(|t| {
                let (spec, nll) = problem.fit_pair_tables(t, other, &|_| true);
                let at = spec.first().map_or(m, |s| if s.1 != 0.0 { s.1 } else { m });
                (emulator.effects[t].parameter(p.name), t, at, nll)
            })
            .collect();
        // By value; of two tables at one value (a variant at the default beside the
        // default itself), the better fit.
        tried.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.3.total_cmp(&y.3)));
        tried.dedup_by(|later, first| later.0 == first.0);
        tried
    };
    let best_of = |tried: &[(f64, usize, f64, f64)]| {
        tried
            .iter()
            .enumerate()
            .min_by(|x, y| x.1 .3.total_cmp(&y.1 .3))
            .map(|(i, _)| i)
    };
    for _ in 0..PAIR_BISECTIONS {
        let tried = tried(emulator);
        tracing::debug!(member, other, mo, ?tried, "bisection beside the leader");
        let Some(i) = best_of(&tried) else {
            break;
        };
        let at = tried[i].2;
        // A bisection's variant is simulated where the best table's pair fit lands, alone
        // and beside `other`: two simulations per value.
        let grid = [at];
        let values: Vec<f64> = tried.iter().map(|x| x.0).collect();
        let before = emulator.effects.len();
        for v in midpoints_beside(p, &values, i) {
            add(emulator, v, &grid, at)?;
        }
        if emulator.effects.len() == before {
            break;
        }
    }
    land_beside(sim, emulator, member, other)
}

/// Two dynamics tables at their magnitudes, as a pair's fit puts them.
type Landing = [(usize, f64); 2];

/// Landing passes of [`land_beside`].
const LANDING_PASSES: usize = 6;
/// Tables of a pair member's family a landing pass simulates where their own pair fit lands.
const LANDING_TABLES: usize = 3;
/// A joint point held within this relative distance of a landing, in both magnitudes, is
/// taken as there.
const LANDING_TOLERANCE: f64 = 0.05;

/// The [`LANDING_TABLES`] tables of dynamics table `member`'s family whose pair fit beside
/// table `other` is best, each simulated where its own pair fit lands: both members alone
/// there (refinement) and together (a joint point), [`LANDING_PASSES`] times or until every
/// such landing holds a joint point. The bisection simulated each variant beside `other`
/// only where the best table's fit landed; between there and 0 a variant's fit rests on the
/// product of the two ratios, while a secondary value that makes the effect act sooner (a
/// friction drift's shorter slip scale) lands well inside that range (docs/results/diagnosis.md,
/// "A pair's landing"). Returns where the best table's pair fit lands after the passes.
fn land_beside(
    sim: Simulating,
    emulator: &mut Emulator,
    member: usize,
    other: usize,
) -> Result<Option<Landing>, GapError> {
    let (campaign, options, configs_dir, control, cache) = sim.parts();
    let mut pass = 0;
    loop {
        let (best, landings): (Option<Landing>, Vec<Landing>) = {
            let problem = FitProblem::new(campaign, emulator, options);
            let mut fits: Vec<(f64, Landing)> = emulator
                .family(member)
                .into_iter()
                .filter_map(|t| {
                    let (spec, nll) = problem.fit_pair_tables(t, other, &|_| true);
                    match spec[..] {
                        [a, b] if a.1 != 0.0 && b.1 != 0.0 => Some((nll, [a, b])),
                        _ => None,
                    }
                })
                .collect();
            fits.sort_by(|x, y| x.0.total_cmp(&y.0));
            for (nll, [a, b]) in &fits {
                tracing::debug!(
                    table = a.0,
                    parameters = ?emulator.effects[a.0].parameters,
                    magnitude = a.1,
                    other = b.1,
                    nll,
                    grid = ?emulator.effects[a.0].magnitudes,
                    "pair landing beside the leader"
                );
            }
            let landings = fits
                .iter()
                .take(LANDING_TABLES)
                .map(|(_, l)| *l)
                .filter(|l| !emulator.joint_near(*l, LANDING_TOLERANCE))
                .collect();
            (fits.first().map(|f| f.1), landings)
        };
        if landings.is_empty() || pass == LANDING_PASSES {
            return Ok(best);
        }
        pass += 1;
        let alone: Vec<(usize, f64)> = landings.iter().flatten().copied().collect();
        emulator.refine(campaign, configs_dir, &alone, control, cache, &|_, _| {})?;
        for [a, b] in landings {
            emulator.add_joint(campaign, configs_dir, a, b, control, cache)?;
        }
    }
}

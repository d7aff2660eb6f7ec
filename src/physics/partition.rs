//! Independent parts of a multibody system.
//!
//! Two dynamic bodies interact only through a contact or a force element between them; a
//! kinematic body (a prescribed motion such as the launcher) moves whatever its forces are, so
//! it couples nothing back. The dynamic bodies therefore fall into independent groups (the
//! connected components of the graph whose edges are the contacts and force elements between
//! dynamic bodies), and each group with the kinematic bodies it touches is a system of its own:
//! its equations do not involve the other groups' states. Integrating each group with its own
//! integrator gives each its own step sizes (one missile's impact does not shorten another's
//! steps) and Newton matrices of its own size, so the cost of N identical groups is N times the
//! cost of one, where one integrator over all of them pays for every group's events at every
//! step and factors a matrix growing with N.

use super::body::BodyKind;
use super::contact::Contact;
use super::forces::{Attachment, ForceElement};
use super::system::MultibodySystem;

/// One independent part: a system of its own and where its pieces sit in the whole.
#[derive(Clone)]
pub struct Part {
    /// The part as a system (its dynamic bodies, the kinematic bodies they touch, their
    /// contacts and force elements, body indices renumbered).
    pub system: MultibodySystem,
    /// Index in the whole system of each of the part's bodies.
    pub bodies: Vec<usize>,
    /// Index in the whole system of each of the part's contacts.
    pub contacts: Vec<usize>,
    /// Index in the whole system of each of the part's force elements.
    pub forces: Vec<usize>,
}

impl Part {
    /// The part's state taken out of the whole system's state `y`.
    pub fn state_from(&self, whole: &MultibodySystem, y: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.system.state_len()];
        for (local, &global) in self.bodies.iter().enumerate() {
            if let (BodyKind::Dynamic { offset: lo }, BodyKind::Dynamic { offset: go }) =
                (&self.system.bodies[local].kind, &whole.bodies[global].kind)
            {
                let len = super::body::BODY_STATE_LEN;
                out[*lo..lo + len].copy_from_slice(&y[*go..go + len]);
            }
        }
        out
    }
}

fn attachments(f: &ForceElement) -> Vec<usize> {
    match f {
        ForceElement::SpringDamper(s) => vec![s.a.body, s.b.body],
        ForceElement::OneSidedSpring(s) => vec![s.a.body, s.b.body],
        ForceElement::ConstantForce(c) => {
            let mut v = vec![c.a.body];
            v.extend(c.reaction.map(|r| r.body));
            v
        }
        ForceElement::Bushing(b) => vec![b.a.body, b.b.body],
    }
}

fn remap_attachment(a: &mut Attachment, map: &dyn Fn(usize) -> usize) {
    a.body = map(a.body);
}

/// Renumbers the bodies a force element attaches to.
pub fn remap_force(f: &mut ForceElement, map: &dyn Fn(usize) -> usize) {
    match f {
        ForceElement::SpringDamper(s) => {
            remap_attachment(&mut s.a, map);
            remap_attachment(&mut s.b, map);
        }
        ForceElement::OneSidedSpring(s) => {
            remap_attachment(&mut s.a, map);
            remap_attachment(&mut s.b, map);
        }
        ForceElement::ConstantForce(c) => {
            remap_attachment(&mut c.a, map);
            if let Some(r) = c.reaction.as_mut() {
                remap_attachment(r, map);
            }
        }
        ForceElement::Bushing(b) => {
            remap_attachment(&mut b.a, map);
            remap_attachment(&mut b.b, map);
        }
    }
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The independent parts of `sys`, in the order of their first dynamic body; one part (the
/// whole system, renumbered identically) when every dynamic body is connected to every other.
/// Bodies, contacts and forces keep their relative order inside each part.
pub fn independent_parts(sys: &MultibodySystem) -> Vec<Part> {
    let nb = sys.bodies.len();
    let dynamic = |i: usize| matches!(sys.bodies[i].kind, BodyKind::Dynamic { .. });
    let mut parent: Vec<usize> = (0..nb).collect();
    let join = |ends: &[usize], parent: &mut Vec<usize>| {
        let dyn_ends: Vec<usize> = ends.iter().copied().filter(|&b| dynamic(b)).collect();
        for w in dyn_ends.windows(2) {
            let (ra, rb) = (find(parent, w[0]), find(parent, w[1]));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    };
    for c in &sys.contacts {
        join(&[c.body_a, c.body_b], &mut parent);
    }
    for f in &sys.forces {
        join(&attachments(f), &mut parent);
    }
    let mut roots: Vec<usize> = Vec::new();
    for i in (0..nb).filter(|&i| dynamic(i)) {
        let r = find(&mut parent, i);
        if !roots.contains(&r) {
            roots.push(r);
        }
    }
    let mut parts = Vec::with_capacity(roots.len());
    for root in roots {
        let in_part = |b: usize, parent: &mut Vec<usize>| dynamic(b) && find(parent, b) == root;
        let contacts: Vec<usize> = (0..sys.contacts.len())
            .filter(|&k| {
                let c = &sys.contacts[k];
                in_part(c.body_a, &mut parent) || in_part(c.body_b, &mut parent)
            })
            .collect();
        let forces: Vec<usize> = (0..sys.forces.len())
            .filter(|&k| {
                attachments(&sys.forces[k])
                    .into_iter()
                    .any(|b| in_part(b, &mut parent))
            })
            .collect();
        // The part's bodies: its dynamic ones and every kinematic body its contacts and forces
        // touch, in the whole system's order.
        let mut used = vec![false; nb];
        for b in 0..nb {
            used[b] = in_part(b, &mut parent);
        }
        for &k in &contacts {
            used[sys.contacts[k].body_a] = true;
            used[sys.contacts[k].body_b] = true;
        }
        for &k in &forces {
            for b in attachments(&sys.forces[k]) {
                used[b] = true;
            }
        }
        let bodies: Vec<usize> = (0..nb).filter(|&b| used[b]).collect();
        let mut map = vec![None; nb];
        for (local, &global) in bodies.iter().enumerate() {
            map[global] = Some(local);
        }
        let part_contacts: Vec<Contact> = contacts
            .iter()
            .map(|&k| {
                let mut c = sys.contacts[k].clone();
                c.body_a = map[c.body_a].expect("contact body in part");
                c.body_b = map[c.body_b].expect("contact body in part");
                c
            })
            .collect();
        let part_forces: Vec<ForceElement> = forces
            .iter()
            .map(|&k| {
                let mut f = sys.forces[k].clone();
                remap_force(&mut f, &|b| {
                    map[b].expect("an attached body belongs to the part")
                });
                f
            })
            .collect();
        let mut system = MultibodySystem::new(
            bodies.iter().map(|&b| sys.bodies[b].clone()).collect(),
            sys.gravity,
            part_forces,
            part_contacts,
        );
        // The whole system's carrier where the part holds it; else, if the whole system has
        // one, the part's own first kinematic body (a launcher station's rail, driven by the
        // same motion as the first station's).
        if let Some(carrier) = sys.carrier() {
            let local = map[carrier].or_else(|| {
                bodies
                    .iter()
                    .position(|&b| matches!(sys.bodies[b].kind, BodyKind::Kinematic(_)))
            });
            if let Some(local) = local {
                system = system.with_carrier(local);
            }
        }
        parts.push(Part {
            system,
            bodies,
            contacts,
            forces,
        });
    }
    parts
}

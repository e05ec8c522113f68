//! What a run reports of its contacts: the impacts, and the closures, releases and friction
//! switches ([`super::jumps`] resolves them; [`super::Trajectory::impacts`] carries them).

/// The impacts of a run, in order of time, row by row: impact k on contact `contact[k]` during
/// step `step[k]` (counted from 1) at time `t[k]`, at the contact configuration q̃ = `q_at(k)`
/// with the momenta `p_before_at(k)` just before and `p_after_at(k)` just after the jump.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Impacts {
    pub dim: usize,
    pub contact: Vec<usize>,
    pub step: Vec<usize>,
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub p_before: Vec<f64>,
    pub p_after: Vec<f64>,
    /// Impacts under the variational law that found no discrete-energy root near the reflection
    /// (grazing, |∇φ·q̇| of order h) and took Newton's law instead.
    pub grazing: usize,
    /// The contacts' closures and releases.
    pub switches: Switches,
}

/// A change of a contact's state: closed, released, stuck (its friction holding its slip at 0:
/// a body resting or rolling) or slipped (sliding from then on).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switch {
    Closed,
    Released,
    Stuck,
    Slipped,
}

/// The closures, releases and friction switches of a run's contacts, in order of time:
/// contact `contact[k]` switched (`kind[k]`) during step `step[k]`, at time `t[k]` and the
/// state (`q_at(k)`, `p_at(k)`).
///
/// A contact closes at the impact that ends its bounces, when the rest of their Zeno series
/// (flights 2v⁺/|a|, 2ev⁺/|a|, … under the normal acceleration a) sums to less than a step:
/// t is then the series' limit t∞ = t_impact + 2v⁺/(|a|(1 − e)) and the state the impact's
/// (the motion is held from the impact on). An arrival without normal velocity closes it at
/// once. It is released at lift-off, where its multiplier λ crosses 0. With friction, a
/// sliding contact sticks where its slip comes to rest with the force it needs within μ_s N,
/// and a stuck one slips where that force reaches μ_s N.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Switches {
    pub contact: Vec<usize>,
    pub step: Vec<usize>,
    pub t: Vec<f64>,
    pub kind: Vec<Switch>,
    pub q: Vec<f64>,
    pub p: Vec<f64>,
}

impl Switches {
    /// Adds a switch.
    pub(in crate::integrators) fn push(
        &mut self,
        contact: usize,
        step: usize,
        t: f64,
        kind: Switch,
        (q, p): (&[f64], &[f64]),
    ) {
        self.contact.push(contact);
        self.step.push(step);
        self.t.push(t);
        self.kind.push(kind);
        self.q.extend_from_slice(q);
        self.p.extend_from_slice(p);
    }

    pub(in crate::integrators) fn append(&mut self, other: &mut Switches) {
        self.contact.append(&mut other.contact);
        self.step.append(&mut other.step);
        self.t.append(&mut other.t);
        self.kind.append(&mut other.kind);
        self.q.append(&mut other.q);
        self.p.append(&mut other.p);
    }

    fn clear(&mut self) {
        self.contact.clear();
        self.step.clear();
        self.t.clear();
        self.kind.clear();
        self.q.clear();
        self.p.clear();
    }

    /// The number of switches.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there were none.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

impl Impacts {
    /// No impacts of n coordinates, with room for `rows` of them.
    pub(in crate::integrators) fn with_capacity(n: usize, rows: usize) -> Self {
        Impacts {
            dim: n,
            contact: Vec::with_capacity(rows),
            step: Vec::with_capacity(rows),
            t: Vec::with_capacity(rows),
            q: Vec::with_capacity(rows * n),
            p_before: Vec::with_capacity(rows * n),
            p_after: Vec::with_capacity(rows * n),
            grazing: 0,
            switches: Switches::default(),
        }
    }

    /// Adds an impact.
    pub(in crate::integrators) fn push(
        &mut self,
        contact: usize,
        step: usize,
        t: f64,
        q: &[f64],
        p_before: &[f64],
        p_after: &[f64],
    ) {
        self.contact.push(contact);
        self.step.push(step);
        self.t.push(t);
        self.q.extend_from_slice(q);
        self.p_before.extend_from_slice(p_before);
        self.p_after.extend_from_slice(p_after);
    }

    /// Moves `other`'s impacts to the end of these, leaving it empty (its storage kept).
    pub fn append(&mut self, other: &mut Impacts) {
        self.contact.append(&mut other.contact);
        self.step.append(&mut other.step);
        self.t.append(&mut other.t);
        self.q.append(&mut other.q);
        self.p_before.append(&mut other.p_before);
        self.p_after.append(&mut other.p_after);
        self.grazing += std::mem::take(&mut other.grazing);
        self.switches.append(&mut other.switches);
    }

    /// Forgets every impact, keeping the storage.
    pub(in crate::integrators) fn clear(&mut self) {
        self.contact.clear();
        self.step.clear();
        self.t.clear();
        self.q.clear();
        self.p_before.clear();
        self.p_after.clear();
        self.grazing = 0;
        self.switches.clear();
    }

    /// The number of impacts.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there were none.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// q̃ of impact k.
    pub fn q_at(&self, k: usize) -> &[f64] {
        &self.q[k * self.dim..(k + 1) * self.dim]
    }

    /// The momenta just before impact k.
    pub fn p_before_at(&self, k: usize) -> &[f64] {
        &self.p_before[k * self.dim..(k + 1) * self.dim]
    }

    /// The momenta just after impact k.
    pub fn p_after_at(&self, k: usize) -> &[f64] {
        &self.p_after[k * self.dim..(k + 1) * self.dim]
    }
}

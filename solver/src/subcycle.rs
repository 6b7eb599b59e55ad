//! Subcycling (mixed time integration by nodal partition): parts whose own stable step is many
//! times the run's step have their interior integrated with a step `k` times longer.
//!
//! # The scheme
//!
//! Belytschko, Yen & Mullen (1979), "Mixed methods for time integration", CMAME 17/18:
//! 259-275, nodal partition; in the notation of Belytschko, Liu & Moran, *Nonlinear Finite
//! Elements for Continua and Structures*, section 6.5.
//!
//! - A part is *slow* when the smallest initial step of its elements, `kappa L / c` over them,
//!   is at least `2 k` times the smallest of the whole model (the factor 2 leaves room for the
//!   steps to shrink as the elements deform). `k` is a power of two, at most the run's
//!   `subcycling` setting; every slow part takes the same `k` (the smallest any of them
//!   allows).
//! - A node is *slow* when every element around it belongs to a slow part and nothing else
//!   acts on it: no kinematic condition, no nodal load, not read by a force stage (contact).
//!   Every other node is *fast*.
//! - An element of a slow part whose eight nodes are all slow is a slow element: it is
//!   evaluated only at the macro times `t_N`, every `k` steps from the first, with the step
//!   `T = t_N - t_(N-1)` passed to its law (viscous and damping history). The other elements,
//!   those of a slow part that touch a fast node, are evaluated every step. The clock never
//!   changes its period: output does not force a macro time, so the motion does not depend on
//!   the output schedule. A slow element's stress is written at each macro time, so an output
//!   step shows the stress of the last one, at most `k - 1` steps earlier.
//! - Fast nodes take the central-difference step `dt` as usual. A slow node takes it with
//!   the macro step: its force (from the slow elements and the interface elements at `t_N`)
//!   acts only at `t_N`, where its velocity update is
//!
//!   ```text
//!   v^(N+1/2) = v^(N-1/2) + (T^(N-1/2) + T^(N+1/2)) / 2 f^N / m,      T^(N+1/2) ~ k dt,
//!   ```
//!
//!   and between macro times only mass-proportional damping (if any) acts on it, so without
//!   damping it moves at constant velocity: the interface elements see its displacement
//!   interpolated linearly in time, as the scheme requires. The update is the ordinary one
//!   with the slow nodes' forces multiplied by `w = (B + k dt) / (dt^(n-1/2) + dt^(n+1/2))`
//!   at macro times and by zero between them ([`Subcycling::weigh`]), so the energy sums of
//!   the update (trapezoidal works) book the slow nodes' work over the macro step.
//!   `T^(N+1/2)` is not known at `t_N` when the step varies, so the forward half uses `k dt`
//!   and the next macro time books the difference: `B = 2 T^(N-1/2) - k dt^(N-1)`, so that
//!   each macro interval's two halves add up to its true length (`B = T^(N-1/2)` at a
//!   constant step). Should the step fall to under half within one macro interval, `B` would
//!   be negative: it is then taken as zero and the rest booked at the next macro time.
//! - Stability: every element of a slow part, slow or at its boundary, reports its step
//!   divided by `k` to the run's step choice, since the slow nodes take the macro step under
//!   the stiffness of both; so `k dt` stays below their stable steps. The factor 2 of the
//!   partition makes that free at the start. Run-time mass scaling keeps its target for those
//!   elements on the same terms (its floor is multiplied by `k`). The fast parts keep theirs
//!   with `dt`. The partition is fixed for the run: should a slow part's elements collapse
//!   until their step over `k` sets the run's step, the run takes shorter steps than it would
//!   without subcycling, and the summary says in how many steps that happened
//!   ([`Subcycling::slow_bound_steps`]). Belytschko & Mullen showed the nodal partition stable under these
//!   element-wise limits for linear systems; Daniel (1997, IJNME 40: 2841-2855) found narrow
//!   unstable bands of the linear-interpolation scheme in undamped systems. The run's
//!   stability guard (negative internal energy, non-finite energies) stops such a run.
//!
//! # What it saves, and what it costs
//!
//! Only the slow elements' force evaluations are saved; interface elements run every step.
//! In the paper's palpation the liver's Ogden + Prony law gives a wave speed of about 13 m/s
//! against the flesh's 1,374 m/s, so most of the liver can step 16 times longer
//! (docs/performance.md, "Subcycling", for the time and the error it costs).

use crate::model::Model;

/// The partition of a subcycled run and the state of its macro clock.
#[derive(Clone, Debug)]
pub struct Subcycling {
    /// Steps per macro step (a power of two, at least 2).
    pub k: u32,
    /// The slow nodes, ascending.
    pub slow_nodes: Vec<u32>,
    /// Names of the slow parts, with how many of their elements are slow out of how many.
    pub parts: Vec<(String, usize, usize)>,
    /// Steps since the last macro time.
    since: u32,
    /// The last macro time t_N (s).
    t_macro: f64,
    /// T^(N-1/2) = t_N - t_(N-1) (s), the macro step that ended at t_N.
    t_before: f64,
    /// Whether the coming update starts at a macro time (the slow nodes' forces apply).
    pending: bool,
    /// The forward half the last macro time assumed, `k dt` (s).
    ahead: f64,
    /// What a backward half could not take (it would have been negative), carried to the
    /// next (s).
    owed: f64,
    /// Per part: whether it is slow.
    slow_part: Vec<bool>,
    /// Steps whose stable step an element of a slow part set (its own over `k`).
    pub slow_bound_steps: u64,
    /// Element evaluations saved so far (slow elements not evaluated in a step).
    pub saved: u64,
    slow_elements: usize,
}

/// What [`plan`] decides: the macro ratio, which elements are slow and which nodes.
pub struct Plan {
    /// Steps per macro step.
    pub k: u32,
    /// Per element (global id): whether it is a slow element.
    pub slow_element: Vec<bool>,
    /// Per part: whether it is slow (its elements report their step over `k`, split or not).
    pub slow_part: Vec<bool>,
    /// The slow nodes, ascending.
    pub slow_nodes: Vec<u32>,
}

/// The largest power of two not above `x` (at least 1).
fn pow2_floor(x: f64) -> u32 {
    let mut k = 1u32;
    while (2 * k) as f64 <= x && k < (1 << 30) {
        k *= 2;
    }
    k
}

/// Partition the model for subcycling with at most `max_ratio` steps per macro step. `pinned`
/// marks the nodes that must stay fast (kinematic conditions, loads, nodes a force stage
/// reads). `part_dt` is each part's smallest initial step (infinite for a part without
/// elements). `None` when no part is slow enough or no element of a slow part is slow.
pub fn plan(model: &Model, part_dt: &[f64], pinned: &[bool], max_ratio: u32) -> Option<Plan> {
    let dt_min = part_dt.iter().copied().fold(f64::INFINITY, f64::min);
    if max_ratio < 2 || !(dt_min > 0.0 && dt_min.is_finite()) {
        return None;
    }
    let ratio: Vec<u32> = part_dt
        .iter()
        .map(|&d| pow2_floor((d / dt_min / 2.0).min(max_ratio as f64)))
        .collect();
    let k = ratio.iter().copied().filter(|&r| r >= 2).min()?;
    let slow_part: Vec<bool> = ratio.iter().map(|&r| r >= 2).collect();
    let mesh = &model.mesh;
    let mut slow_node = vec![true; mesh.nodes.len()];
    for (e, conn) in mesh.elements.iter().enumerate() {
        if !slow_part[mesh.element_part[e] as usize] {
            for &n in conn {
                slow_node[n as usize] = false;
            }
        }
    }
    for (s, &p) in slow_node.iter_mut().zip(pinned) {
        *s &= !p;
    }
    let slow_element: Vec<bool> = mesh
        .elements
        .iter()
        .enumerate()
        .map(|(e, c)| {
            slow_part[mesh.element_part[e] as usize] && c.iter().all(|&n| slow_node[n as usize])
        })
        .collect();
    if !slow_element.iter().any(|&s| s) {
        return None;
    }
    let slow_nodes = (0..mesh.nodes.len() as u32)
        .filter(|&n| slow_node[n as usize])
        .collect();
    Some(Plan {
        k,
        slow_element,
        slow_part,
        slow_nodes,
    })
}

impl Subcycling {
    /// The macro clock of a run partitioned by `plan` (`parts` as
    /// [`Model::split_for_subcycling`] reports them), before its first force evaluation.
    pub fn new(plan: Plan, parts: Vec<(String, usize, usize)>) -> Subcycling {
        Subcycling {
            k: plan.k,
            slow_nodes: plan.slow_nodes,
            slow_elements: parts.iter().map(|p| p.1).sum(),
            parts,
            since: 0,
            t_macro: 0.0,
            t_before: 0.0,
            pending: false,
            ahead: 0.0,
            owed: 0.0,
            slow_part: plan.slow_part,
            slow_bound_steps: 0,
            saved: 0,
        }
    }

    /// Count a step whose stable step an element of part `part` set (see
    /// [`Subcycling::slow_bound_steps`]).
    pub fn note_step_set_by(&mut self, part: usize) {
        if self.slow_part.get(part) == Some(&true) {
            self.slow_bound_steps += 1;
        }
    }

    /// Whether the force evaluation at time `t` is a macro time: the first one and every
    /// `k`-th step after it. On a macro time returns `Some(T)`, the macro step that ends there
    /// (the step the slow elements' laws take), and starts the next macro step.
    pub fn evaluation(&mut self, t: f64, first: bool) -> Option<f64> {
        if first || self.since >= self.k {
            let big = if first { 0.0 } else { t - self.t_macro };
            self.t_before = big;
            self.t_macro = t;
            self.since = 0;
            self.pending = true;
            Some(big)
        } else {
            self.saved += self.slow_elements as u64;
            None
        }
    }

    /// Weigh the slow nodes' forces for the update from t^n with the step `dt` (the step
    /// before was `dt_old`): by `(B + k dt) / (dt_old + dt)` at a macro time, with
    /// `B = 2 T^(N-1/2) - k dt^(N-1)` the backward half that completes the last macro
    /// interval; else by zero (see the module doc). Advances the clock by one step.
    pub fn weigh(&mut self, f_int: &mut [[f64; 3]], f_ext: &mut [[f64; 3]], dt: f64, dt_old: f64) {
        let w = if self.pending {
            // negative only when the step fell to under half within a macro interval: the
            // rest is booked at the next macro time, so the halves still add up
            let back = 2.0 * self.t_before - self.ahead - self.owed;
            self.owed = (-back).max(0.0);
            let back = back.max(0.0);
            self.ahead = self.k as f64 * dt;
            (back + self.ahead) / (dt_old + dt)
        } else {
            0.0
        };
        self.pending = false;
        self.since += 1;
        for &n in &self.slow_nodes {
            let (fi, fe) = (&mut f_int[n as usize], &mut f_ext[n as usize]);
            for d in 0..3 {
                fi[d] *= w;
                fe[d] *= w;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::pow2_floor;

    #[test]
    fn powers_of_two_below() {
        assert_eq!(pow2_floor(0.3), 1);
        assert_eq!(pow2_floor(1.0), 1);
        assert_eq!(pow2_floor(3.99), 2);
        assert_eq!(pow2_floor(4.0), 4);
        assert_eq!(pow2_floor(50.0), 32);
    }
}

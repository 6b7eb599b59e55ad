//! Axis-aligned bounding boxes: the broad phase of the contact stage, the bounds of a shape
//! and the nodes of a triangle mesh's BVH.

use crate::vec3::add;

/// Axis-aligned bounding box (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner (m).
    pub min: [f64; 3],
    /// Upper corner (m).
    pub max: [f64; 3],
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf).
    pub const EMPTY: Aabb = Aabb {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };
    /// Grow to contain `p`.
    #[inline]
    pub fn include(&mut self, p: [f64; 3]) {
        for (k, pk) in p.iter().enumerate() {
            self.min[k] = self.min[k].min(*pk);
            self.max[k] = self.max[k].max(*pk);
        }
    }
    /// Grow by `m` on every side.
    #[inline]
    pub fn inflated(&self, m: f64) -> Aabb {
        Aabb {
            min: [self.min[0] - m, self.min[1] - m, self.min[2] - m],
            max: [self.max[0] + m, self.max[1] + m, self.max[2] + m],
        }
    }
    /// Translate by `u`.
    #[inline]
    pub fn translated(&self, u: [f64; 3]) -> Aabb {
        Aabb {
            min: add(self.min, u),
            max: add(self.max, u),
        }
    }
    /// Whether the two boxes overlap (closed intervals).
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        (0..3).all(|k| self.min[k] <= o.max[k] && o.min[k] <= self.max[k])
    }
    /// Squared distance from `p` to the box (0 inside).
    #[inline]
    pub fn distance2(&self, p: [f64; 3]) -> f64 {
        let mut d2 = 0.0;
        for (k, pk) in p.iter().enumerate() {
            let d = (self.min[k] - pk).max(pk - self.max[k]).max(0.0);
            d2 += d * d;
        }
        d2
    }
}

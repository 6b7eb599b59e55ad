//! The body plan as implicit functions: every point of space gets a label.
//!
//! Frame (see the module docs of `phantom`): x towards the patient's left, y cranial,
//! z anterior; the back lies on z = 0, the torso spans y in [0, L], the midline is x = 0.
//! Positions below are quoted for the default 300 x 220 x 300 mm torso and measured down
//! from the cranial end (so they follow a longer or shorter torso); `xr = -x` is the
//! distance towards the patient's right.
//!
//! - **Torso**: a superellipse |x/a|^p + |(z - zc)/b|^p <= 1 (a = width/2, p = 2.2),
//!   flattened at z = 0 where the back lies on the table (10 mm of the ellipse cut off).
//!   depth(x, z) = distance to that outline, from a 1 mm distance table of the polygon.
//! - **Flesh**: depth < fat + 12 mm (fat, then the muscle and rib layer).
//! - **Ribs 6-12**: bars 12 mm wide (cranio-caudal) and 9 mm thick (radial) at depth
//!   fat + 1 mm, running around the body at the polar angle theta = atan2(|x|, zc - z)
//!   (0 = posterior midline, pi = anterior midline) and sloping caudally towards the front:
//!   y(theta) linear from the posterior end to the tip. Ribs 7-10 end on the costal margin,
//!   which runs from the xiphoid (midline, 68 mm below the top) down and out to rib 10
//!   (theta = 0.55 pi, 160 mm below the top); the costal cartilage is a bar along it, and
//!   the sternum a 32 mm wide plate above the xiphoid. Ribs 11-12 float.
//! - **Liver** (right upper quadrant, crossing the midline): the intersection of
//!   (a) depth >= fat + 12 mm (+ up to 22 mm more towards the midline, where the rectus
//!   sheath is thicker), (b) below a dome y <= y_dome(xr, z) (the right hemidiaphragm),
//!   (c) above a posterior floor z >= z_post(xr) that rises towards the thin left lobe, and
//!   (d) the concave visceral surface y - y_edge(xr) >= dz - 5 dz^2 (dz = depth below the
//!   liver's anterior surface, m), which leaves the anterior surface at 45 degrees and curves
//!   back down over the thick posterior right lobe: the sharp inferior edge y_edge(xr), lowest on the
//!   right (165 mm below the top) and rising to the left, about 30 mm below the costal margin
//!   in the right mid-clavicular line. (a)-(c) are blended with a polynomial smooth minimum
//!   (Quilez, k = 12 mm) for a rounded wedge; (d) is joined with k = 2 mm to keep the edge
//!   sharp. The respiratory phase moves the liver caudally by `phase * max_liver_shift`.
//! - **Spine**: an elliptic column (28 x 35 mm half axes) centred 55 mm above the back.
//! - **Viscera**: everything else inside the flesh layer.
//! - **Tumours**: balls intersected with the liver.
//!
//! Priority where shapes overlap: ribs, spine, tumour, liver, flesh, viscera.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::params::PhantomParams;

/// Label of background.
pub const BACKGROUND: u8 = 0;
/// Label of the subcutaneous flesh and abdominal wall.
pub const FLESH: u8 = 1;
/// Label of the liver.
pub const LIVER: u8 = 2;
/// Label of the ribs, costal cartilage and sternum.
pub const RIBS: u8 = 3;
/// Label of the lumped viscera.
pub const VISCERA: u8 = 4;
/// Label of the spine.
pub const SPINE: u8 = 5;
/// Label of the first tumour (tumour n has label `TUMOUR + n`).
pub const TUMOUR: u8 = 6;

const P_EXP: f64 = 2.2;
const BACK_FLAT: f64 = 0.010;
const WALL: f64 = 0.012;
const DF_STEP: f64 = 0.001;

/// One rib's centre line y(theta), linear between its posterior end and its tip.
#[derive(Clone, Copy, Debug)]
struct Rib {
    y_post: f64,
    theta_tip: f64,
    y_tip: f64,
}

const THETA0: f64 = 0.08 * PI;

/// The evaluated body plan.
pub struct Anatomy {
    a: f64,
    b: f64,
    zc: f64,
    top: f64,
    fat: f64,
    shift: f64,
    rib_w: f64,
    rib_t: f64,
    ribs: Vec<Rib>,
    tumours: Vec<([f64; 3], f64)>,
    // distance table over x in [x0, x0 + nx*step], z in [z0, ...]
    df: Vec<f32>,
    df_n: [usize; 2],
    df_o: [f64; 2],
}

fn smin(a: f64, b: f64, k: f64) -> f64 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl Anatomy {
    /// Build the body plan for `p` (the distance table takes a fraction of a second).
    pub fn new(p: &PhantomParams) -> Self {
        let a = p.torso_width / 2.0;
        let b = (p.torso_depth + BACK_FLAT) / 2.0;
        let zc = b - BACK_FLAT;
        let top = p.torso_length;
        let h = p.voxel;
        let mut an = Anatomy {
            a,
            b,
            zc,
            top,
            fat: p.fat_thickness,
            shift: p.liver_shift(),
            rib_w: 0.012f64.max(1.5 * h),
            rib_t: 0.009f64.max(1.5 * h),
            ribs: Vec::new(),
            tumours: p.tumours.iter().map(|t| (t.center, t.radius)).collect(),
            df: Vec::new(),
            df_n: [0, 0],
            df_o: [0.0, 0.0],
        };
        // ribs 6..12: (posterior end, tip angle / pi, tip height or None = on the costal margin)
        let design: [(f64, f64, Option<f64>); 7] = [
            (0.300, 0.93, Some(0.258)),
            (0.282, 0.82, None),
            (0.262, 0.73, None),
            (0.242, 0.64, None),
            (0.222, 0.56, None),
            (0.202, 0.42, Some(0.135)),
            (0.182, 0.30, Some(0.140)),
        ];
        for (yp, tt, yt) in design {
            let theta_tip = tt * PI;
            let y_tip = yt
                .map(|y| an.yd(y))
                .unwrap_or_else(|| an.costal_margin(theta_tip) + an.rib_w / 2.0);
            an.ribs.push(Rib {
                y_post: an.yd(yp),
                theta_tip,
                y_tip,
            });
        }
        an.build_distance_table();
        an
    }

    /// A design height (quoted for a 300 mm torso) anchored to the cranial end.
    fn yd(&self, y: f64) -> f64 {
        self.top - (0.300 - y)
    }

    /// Top (anterior) surface height of the torso at x (m).
    pub fn skin_z(&self, x: f64) -> f64 {
        let u = (x.abs() / self.a).min(1.0).powf(P_EXP);
        self.zc + self.b * (1.0 - u).max(0.0).powf(1.0 / P_EXP)
    }

    /// Inside the torso outline?
    pub fn inside(&self, x: f64, z: f64) -> bool {
        z >= 0.0
            && (x.abs() / self.a).powf(P_EXP) + ((z - self.zc).abs() / self.b).powf(P_EXP) <= 1.0
    }

    fn outline(&self, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|q| {
                let t = 2.0 * PI * q as f64 / n as f64;
                let (c, s) = (t.cos(), t.sin());
                let x = self.a * c.signum() * c.abs().powf(2.0 / P_EXP);
                let z = self.zc + self.b * s.signum() * s.abs().powf(2.0 / P_EXP);
                [x, z.max(0.0)]
            })
            .collect()
    }

    fn build_distance_table(&mut self) {
        let poly = self.outline(1200);
        let x0 = -self.a - 0.005;
        let z0 = -0.005;
        let nx = ((2.0 * self.a + 0.01) / DF_STEP).ceil() as usize + 2;
        let nz = ((self.zc + self.b + 0.01) / DF_STEP).ceil() as usize + 2;
        self.df_o = [x0, z0];
        self.df_n = [nx, nz];
        let me = &*self;
        let rows: Vec<Vec<f32>> = (0..nz)
            .into_par_iter()
            .map(|kz| {
                let z = z0 + kz as f64 * DF_STEP;
                (0..nx)
                    .map(|ix| {
                        let x = x0 + ix as f64 * DF_STEP;
                        let mut d2 = f64::INFINITY;
                        for q in 0..poly.len() {
                            let (p0, p1) = (poly[q], poly[(q + 1) % poly.len()]);
                            let (ex, ez) = (p1[0] - p0[0], p1[1] - p0[1]);
                            let l2 = ex * ex + ez * ez;
                            let t = if l2 > 0.0 {
                                (((x - p0[0]) * ex + (z - p0[1]) * ez) / l2).clamp(0.0, 1.0)
                            } else {
                                0.0
                            };
                            let (dx, dz) = (x - p0[0] - t * ex, z - p0[1] - t * ez);
                            d2 = d2.min(dx * dx + dz * dz);
                        }
                        let d = d2.sqrt();
                        (if me.inside(x, z) { d } else { -d }) as f32
                    })
                    .collect()
            })
            .collect();
        self.df = rows.concat();
    }

    /// Signed distance to the torso outline in the cross-section (m), positive inside.
    pub fn depth(&self, x: f64, z: f64) -> f64 {
        let fx = (x - self.df_o[0]) / DF_STEP;
        let fz = (z - self.df_o[1]) / DF_STEP;
        if fx < 0.0
            || fz < 0.0
            || fx >= (self.df_n[0] - 1) as f64
            || fz >= (self.df_n[1] - 1) as f64
        {
            return -1.0;
        }
        let (ix, iz) = (fx as usize, fz as usize);
        let (tx, tz) = (fx - ix as f64, fz - iz as f64);
        let g = |i: usize, k: usize| self.df[i + self.df_n[0] * k] as f64;
        (1.0 - tz) * ((1.0 - tx) * g(ix, iz) + tx * g(ix + 1, iz))
            + tz * ((1.0 - tx) * g(ix, iz + 1) + tx * g(ix + 1, iz + 1))
    }

    /// Polar angle around the torso centre, 0 at the posterior midline, pi anterior.
    pub fn theta(&self, x: f64, z: f64) -> f64 {
        x.abs().atan2(self.zc - z)
    }

    /// Lower edge of the costal margin (m) at polar angle theta in [0.55 pi, pi].
    pub fn costal_margin(&self, theta: f64) -> f64 {
        let t = ((theta / PI - 0.55) / 0.45).clamp(0.0, 1.0);
        self.yd(0.140) + t * (self.yd(0.232) - self.yd(0.140))
    }

    /// Is the point in a rib, the costal cartilage or the sternum?
    pub fn in_ribs(&self, x: f64, y: f64, z: f64, depth: f64) -> bool {
        let d0 = self.fat + 0.001;
        if depth < d0 || depth > d0 + self.rib_t {
            return false;
        }
        let th = self.theta(x, z);
        let hw = self.rib_w / 2.0;
        for r in &self.ribs {
            if th >= THETA0 && th <= r.theta_tip {
                let yc = r.y_post + (th - THETA0) / (r.theta_tip - THETA0) * (r.y_tip - r.y_post);
                if (y - yc).abs() <= hw {
                    return true;
                }
            }
        }
        // costal cartilage along the margin, from rib 10 to the xiphoid
        if th >= 0.56 * PI {
            let ym = self.costal_margin(th);
            if y >= ym && y <= ym + self.rib_w {
                return true;
            }
        }
        // sternum above the xiphoid
        x.abs() <= 0.016 && y >= self.yd(0.225)
    }

    /// Inferior edge height of the liver (m) at xr = -x, before the respiratory shift.
    pub fn liver_edge(&self, xr: f64) -> f64 {
        self.yd(0.135) + 0.45 * (0.130 - xr)
    }

    fn liver_front_depth(&self, xr: f64) -> f64 {
        self.fat + WALL + 0.022 * (1.0 - smoothstep(0.0, 0.07, xr))
    }

    /// Signed liver margin (m, positive inside) at a point, before tumours.
    pub fn liver_margin(&self, x: f64, y: f64, z: f64, depth: f64) -> f64 {
        let y = y + self.shift; // the liver moves caudally by `shift`
        let xr = -x;
        let front = self.liver_front_depth(xr);
        let s_wall = depth - front;
        let y_dome = self.yd(0.292) - 2.5 * (xr - 0.06).powi(2) - 2.0 * (z - 0.12).powi(2);
        let s_dome = y_dome - y;
        let z_front = self.skin_z(x) - front;
        let z_post = if xr >= 0.04 {
            0.035
        } else {
            0.035 + (0.04 - xr) / 0.14 * ((z_front - 0.025) - 0.035)
        };
        let s_post = z - z_post;
        let dz = (z_front - z).max(0.0);
        let s_visc = (y - self.liver_edge(xr) - (dz - 5.0 * dz * dz)) / std::f64::consts::SQRT_2;
        let k = 0.012;
        let s = smin(smin(s_wall, s_dome, k), s_post, k);
        smin(s, s_visc, 0.002)
    }

    /// Label of the point (x, y, z) (m).
    pub fn label(&self, x: f64, y: f64, z: f64) -> u8 {
        if y < 0.0 || y > self.top || !self.inside(x, z) {
            return BACKGROUND;
        }
        let d = self.depth(x, z).max(0.0);
        if self.in_ribs(x, y, z, d) {
            return RIBS;
        }
        if (x / 0.028).powi(2) + ((z - 0.055) / 0.035).powi(2) <= 1.0 {
            return SPINE;
        }
        if self.liver_margin(x, y, z, d) > 0.0 {
            for (n, (c, r)) in self.tumours.iter().enumerate() {
                let (dx, dy, dz) = (x - c[0], y + self.shift - c[1], z - c[2]);
                if dx * dx + dy * dy + dz * dz <= r * r {
                    return TUMOUR + n as u8;
                }
            }
            return LIVER;
        }
        if d < self.fat + WALL {
            FLESH
        } else {
            VISCERA
        }
    }

    /// A point on the liver's inferior edge (at its anterior surface) at x, after the shift.
    pub fn liver_edge_point(&self, x: f64) -> [f64; 3] {
        let xr = -x;
        [
            x,
            self.liver_edge(xr) - self.shift,
            self.skin_z(x) - self.liver_front_depth(xr),
        ]
    }

    /// Half width of the torso (m).
    pub fn half_width(&self) -> f64 {
        self.a
    }

    /// Height of the torso's top (m).
    pub fn height(&self) -> f64 {
        self.zc + self.b
    }

    /// Height of the torso outline's centre (m): points above it are in the anterior half.
    pub fn centre_height(&self) -> f64 {
        self.zc
    }

    /// Length of the torso, caudal to cranial (m).
    pub fn length(&self) -> f64 {
        self.top
    }

    /// Caudal liver shift (m).
    pub fn shift(&self) -> f64 {
        self.shift
    }
}

//! Shared helpers for the contact tests: flat quad grids and a spring-supported surface.
#![allow(dead_code)]
#![allow(clippy::needless_range_loop)]

use contact::*;

/// A flat `n x n` grid of square faces of size `h` (m) in the plane z = 0
/// ([`ContactSurface::flat_grid`]). Returns (positions, surface).
pub fn flat_grid(n: usize, h: f64, bulk: f64) -> (Vec<[f64; 3]>, ContactSurface) {
    ContactSurface::flat_grid(n, h, bulk)
}

pub fn sphere(name: &str, center: [f64; 3], radius: f64, motion: MotionSpec) -> IndenterSpec {
    IndenterSpec {
        name: name.into(),
        parts: vec![ShapeSpec::Sphere { center, radius }],
        direction: [0.0, 0.0, -1.0],
        motion,
        friction: None,
    }
}

pub fn sum_forces(f: &[[f64; 3]]) -> [f64; 3] {
    let mut s = [0.0; 3];
    for v in f {
        for k in 0..3 {
            s[k] += v[k];
        }
    }
    s
}

/// A surface whose nodes hang on springs to their reference positions (a Winkler foundation),
/// integrated with the central-difference scheme. Returns nothing; the caller drives it.
pub struct SpringSurface {
    pub x0: Vec<[f64; 3]>,
    pub x: Vec<[f64; 3]>,
    pub v: Vec<[f64; 3]>,
    pub f: Vec<[f64; 3]>,
    pub mass: f64,
    pub k: f64,
    pub c: f64,
    pub damping_dissipated: f64,
    /// Move nodes only along z (a laterally rigid Winkler foundation).
    pub vertical_only: bool,
}

impl SpringSurface {
    pub fn new(x0: Vec<[f64; 3]>, mass: f64, k: f64, c: f64) -> Self {
        let n = x0.len();
        SpringSurface {
            x: x0.clone(),
            x0,
            v: vec![[0.0; 3]; n],
            f: vec![[0.0; 3]; n],
            mass,
            k,
            c,
            damping_dissipated: 0.0,
            vertical_only: false,
        }
    }
    /// One central-difference step: forces at x_n (contact at time t), then v_{n+1/2}, x_{n+1}.
    pub fn step(&mut self, stage: &mut ContactStage, t: f64, dt: f64) {
        for f in self.f.iter_mut() {
            *f = [0.0; 3];
        }
        stage.apply(t, dt, &self.x, &self.v, &mut self.f);
        for i in 0..self.x.len() {
            let k0 = if self.vertical_only { 2 } else { 0 };
            for k in k0..3 {
                let fd = -self.c * self.v[i][k];
                self.damping_dissipated += -fd * self.v[i][k] * dt;
                let a = (self.f[i][k] - self.k * (self.x[i][k] - self.x0[i][k]) + fd) / self.mass;
                self.v[i][k] += dt * a;
                self.x[i][k] += dt * self.v[i][k];
            }
        }
    }
    pub fn spring_energy(&self) -> f64 {
        let mut e = 0.0;
        for (x, x0) in self.x.iter().zip(&self.x0) {
            for k in 0..3 {
                e += 0.5 * self.k * (x[k] - x0[k]).powi(2);
            }
        }
        e
    }
    pub fn kinetic_energy(&self) -> f64 {
        self.v
            .iter()
            .map(|v| 0.5 * self.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))
            .sum()
    }
}

//! The contact stage of the time loop: the `contact` crate's penalty contact behind the solver's
//! [`ForceStage`] interface. A scene builds it from its `[[indenter]]`, `[[hand]]` and `[contact]`
//! tables (the `scene` crate's `contact_build`; its `contact_spec` documents the format and the
//! default penalty).
//!
//! ## Surface
//! The contact surface is the mesh boundary ([`crate::mesh::Mesh::boundary_faces`], outward
//! quads), optionally restricted to the faces whose four nodes all lie in `[contact] surface`
//! (a node set) and to the elements of `[contact] parts`. Per face the segment formula gets
//! `K = rho c0^2` of the owning element's law (the P-wave modulus `lambda + 2 mu` at the
//! reference state, from [`material::Material::initial_wave_speed`] and the density) and the
//! element's reference volume; the soft formula and the time-step bound use the lumped nodal
//! masses of the model (after mass scaling).
//!
//! ## Time step
//! The crate bounds the contact alone by `dt_c = min_a 2 sqrt(m_a / k_a)` (Gershgorin row sums
//! of the penalty stiffness). The largest eigenvalues of element and contact stiffness add at
//! most, so body plus contact is stable when `(dt/dt_e)^2 + (dt/dt_c)^2 <= 1`. The solver already
//! keeps `dt <= f dt_e` (`f` = `dt_factor`, 0.9; `dt_e` the body's critical step, element by
//! element or from the mesh's largest eigenvalue, [`crate::global_step`]), so this stage's
//! [`ForceStage::max_dt`] is `dt_c sqrt(1 - f^2)` (with `f` taken as at most 0.9). With the
//! default penalty (capped at `k_a <= 0.1 m_a (2/dt_0)^2`, `dt_0` the design step) this is
//! `1.38 dt_0`: it never binds on the element estimate; it binds when a scene raises the
//! penalty beyond the cap, and then it lowers the step instead of letting the run blow up, and
//! it binds under the global estimate when that allows more than 1.38 times the design step
//! (the 3 mm phantom: 1.34 us against the mesh's 1.53 us).
//!
//! ## Energy
//! The crate's identity is `KE + IE + E_contact = W_other + W_drive`, with `E_contact` the stored
//! penalty energy plus contact dissipation and `W_drive` the work of the indenter drivers. The
//! solver's own external-work sum includes the work of the contact forces on the body, so this
//! stage also accumulates that work, `W_body = sum_n (f^(n-1) + f^n)/2 . v^(n-1/2) (t^n - t^(n-1))`
//! over the nodes that carry contact force (the same trapezoidal rule as the solver's sums), and
//! the simulation books `W_external = W_solver - W_body + W_drive` and `E_contact`. The balance then
//! checks the contact too: it closes only if the contact forces are the gradient of the penalty
//! energy and the driver work is right.
//!
//! ## Output
//! Per indenter, `history.csv` gets `<name>_force_x/_y/_z`: the force the body exerts on the
//! indenter (N), i.e. the resultant on the rigid (master) side as LS-DYNA's RCFORC reports it
//! for a rigid master surface: pressing down (-z) into a body gives a positive `force_z`;
//! `<name>_reaction`: that force along `-direction` (N, positive when pressing);
//! `<name>_travel`: the indenter's travel along its direction (m); `<name>_depth`: travel since
//! first contact (m); `<name>_area`: current area of the penetrating sample points (m^2);
//! `<name>_max_penetration` (m). The VTK frames get `contact_pressure` (Pa), per node the mean of
//! the contact pressures of its surface faces, and each frame the indenters' surfaces (see
//! [`crate::output::vtk::write_surfaces`]).

use crate::output::vtk::RigidSurface;
use crate::simulation::ForceStage;
use contact::{ContactStage, IndenterSpec};

/// The contact stage: the `contact` crate's [`ContactStage`] plus the bookkeeping the solver needs
/// (the work of the contact forces on the body, the time-step bound, output columns and fields).
pub struct ContactForceStage {
    stage: ContactStage,
    faces: Vec<[u32; 4]>,
    /// The nodes of the stage's faces, ascending: the only positions it reads.
    face_nodes: Vec<u32>,
    /// Contact forces of the last evaluation (N), nonzero only on `nodes`.
    fc: Vec<[f64; 3]>,
    mark: Vec<bool>,
    nodes: Vec<u32>,
    /// Surface faces per node (for the nodal pressure average).
    node_faces: Vec<u32>,
    body_work: f64,
    t_prev: Option<f64>,
    max_dt: f64,
    columns: Vec<String>,
    /// Indenter surfaces at t = 0, in the order of the stage's indenters.
    drawn: Vec<RigidSurface>,
}

impl ContactForceStage {
    /// Wrap a contact stage. `faces` must be the surface faces the stage was built with,
    /// `specs` its indenters (drawn in the frames), `dt_factor` the solver's time-step factor.
    pub fn new(
        stage: ContactStage,
        specs: &[IndenterSpec],
        faces: Vec<[u32; 4]>,
        n_nodes: usize,
        dt_factor: f64,
    ) -> Self {
        let mut node_faces = vec![0u32; n_nodes];
        for f in &faces {
            for &a in f {
                node_faces[a as usize] += 1;
            }
        }
        let f = dt_factor.min(0.9);
        let max_dt = stage.stable_dt_bound() * (1.0 - f * f).sqrt();
        let mut columns = Vec::new();
        for s in stage.indenters() {
            for c in [
                "force_x",
                "force_y",
                "force_z",
                "reaction",
                "travel",
                "depth",
                "area",
                "max_penetration",
            ] {
                columns.push(format!("{}_{c}", s.name));
            }
        }
        // The positions the stage reads: its own faces' nodes (the stage's, not `faces`, so
        // that they cannot differ).
        let mut face_nodes: Vec<u32> = stage.faces().iter().flatten().copied().collect();
        face_nodes.sort_unstable();
        face_nodes.dedup();
        ContactForceStage {
            stage,
            face_nodes,
            faces,
            fc: vec![[0.0; 3]; n_nodes],
            mark: vec![false; n_nodes],
            nodes: Vec::with_capacity(n_nodes.min(1 << 16)),
            node_faces,
            body_work: 0.0,
            t_prev: None,
            max_dt,
            columns,
            drawn: surfaces_of(specs),
        }
    }
}

#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl ForceStage for ContactForceStage {
    fn name(&self) -> &'static str {
        "contact"
    }

    fn apply(&mut self, t: f64, dt: f64, x: &[[f64; 3]], v: &[[f64; 3]], force: &mut [[f64; 3]]) {
        let dtp = self.t_prev.map_or(0.0, |tp| t - tp);
        self.t_prev = Some(t);
        // f^(n-1) . v^(n-1/2) dt / 2, and clear the previous forces.
        let mut w = 0.0;
        for &a in &self.nodes {
            let a = a as usize;
            w += dot(self.fc[a], v[a]);
            self.fc[a] = [0.0; 3];
            self.mark[a] = false;
        }
        self.nodes.clear();
        self.stage.apply(t, dt, x, v, &mut self.fc);
        for &fi in self.stage.touched_faces() {
            for &a in &self.faces[fi as usize] {
                if !self.mark[a as usize] {
                    self.mark[a as usize] = true;
                    self.nodes.push(a);
                }
            }
        }
        // f^n . v^(n-1/2) dt / 2, and add the forces to the solver's array.
        for &a in &self.nodes {
            let a = a as usize;
            let f = self.fc[a];
            w += dot(f, v[a]);
            let o = &mut force[a];
            o[0] += f[0];
            o[1] += f[1];
            o[2] += f[2];
        }
        self.body_work += 0.5 * dtp * w;
    }

    fn nodes_read(&self) -> Option<&[u32]> {
        Some(&self.face_nodes)
    }

    fn energy(&self) -> f64 {
        self.stage.energy()
    }

    fn body_work(&self) -> f64 {
        self.body_work
    }

    fn driver_work(&self) -> f64 {
        self.stage.driver_work()
    }

    fn max_dt(&self) -> f64 {
        self.max_dt
    }

    fn history_columns(&self) -> Vec<String> {
        self.columns.clone()
    }

    fn surfaces(&self) -> Vec<RigidSurface> {
        self.drawn
            .iter()
            .zip(self.stage.indenters())
            .filter(|(d, _)| !d.polygons.is_empty())
            .map(|(d, s)| RigidSurface {
                displacement: s.offset,
                ..d.clone()
            })
            .collect()
    }

    fn history_values(&self, out: &mut Vec<f64>) {
        for s in self.stage.indenters() {
            out.extend([
                s.force[0],
                s.force[1],
                s.force[2],
                s.reaction,
                s.travel,
                s.depth,
                s.area,
                s.max_penetration,
            ]);
        }
    }

    fn point_fields(&self) -> Vec<(String, Vec<f64>)> {
        let mut p = vec![0.0; self.node_faces.len()];
        for (f, &pf) in self.faces.iter().zip(self.stage.face_pressure()) {
            if pf != 0.0 {
                for &a in f {
                    p[a as usize] += pf;
                }
            }
        }
        for (p, &n) in p.iter_mut().zip(&self.node_faces) {
            if n > 0 {
                *p /= n as f64;
            }
        }
        vec![("contact_pressure".into(), p)]
    }
}

/// Segments around a great circle of the indenter surfaces drawn in the frames.
const DRAW_SEGMENTS: usize = 32;

/// The surfaces of the indenters at t = 0, for the frames: analytic shapes tessellated
/// ([`contact::tessellate::surface`]), triangle meshes as they are; an infinite plane is not
/// drawn.
fn surfaces_of(specs: &[IndenterSpec]) -> Vec<RigidSurface> {
    specs
        .iter()
        .map(|spec| {
            let mut s = RigidSurface {
                name: spec.name.clone(),
                vertices: Vec::new(),
                polygons: Vec::new(),
                displacement: [0.0; 3],
            };
            for part in &spec.parts {
                let base = s.vertices.len() as u32;
                match contact::tessellate::surface(part, DRAW_SEGMENTS) {
                    Ok(q) => {
                        s.vertices.extend(q.verts);
                        s.polygons.extend(
                            q.quads
                                .iter()
                                .map(|q| q.iter().map(|&i| base + i).collect()),
                        );
                    }
                    Err(_) => {
                        if let Ok(contact::Shape::Mesh(m)) = contact::Shape::from_spec(part) {
                            s.vertices.extend_from_slice(m.vertices());
                            s.polygons.extend(
                                m.triangles()
                                    .iter()
                                    .map(|t| t.iter().map(|&i| base + i).collect()),
                            );
                        }
                    }
                }
            }
            s
        })
        .collect()
}

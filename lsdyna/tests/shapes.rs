//! The hollow meshes of the indenter shapes (contact::tessellate), checked with the solver's
//! Jacobians and boundary faces.

use contact::tessellate::*;
use contact::ShapeSpec;

fn check(m: &HexMesh, shape: &ShapeSpec) {
    let s = contact::Shape::from_spec(shape).unwrap();
    for (k, e) in m.elements.iter().enumerate() {
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| m.nodes[e[a] as usize]);
        let (det, _) = solver::hex::corner_jacobians(&x);
        assert!(det.iter().all(|&d| d > 0.0), "element {k}: {det:?}");
    }
    // Outer nodes on the surface, inner ones inside; the boundary is closed.
    let mut mesh = solver::mesh::Mesh {
        nodes: m.nodes.clone(),
        elements: m.elements.clone(),
        ..Default::default()
    };
    mesh.element_part = vec![0; m.elements.len()];
    let faces = mesh.boundary_faces();
    let expected = if m.elements.len() == 1 {
        6
    } else {
        2 * m.elements.len()
    };
    assert_eq!(faces.len(), expected);
    for p in &m.nodes {
        assert!(s.signed_distance(*p).0 < 1e-12, "{p:?}");
    }
}

#[test]
fn shapes_mesh_with_positive_jacobians_and_nodes_on_the_surface() {
    let sp = ShapeSpec::Sphere {
        center: [0.0, 0.0, 0.005],
        radius: 0.005,
    };
    let m = mesh(&sp, 32).unwrap();
    check(&m, &sp);
    assert_eq!(m.elements.len(), 6 * 8 * 8);
    let cap = ShapeSpec::Capsule {
        center: [0.01, 0.0, 0.0075],
        axis: [0.1, 0.2, 1.0],
        radius: 0.0075,
        length: 0.045,
    };
    check(&mesh(&cap, 64).unwrap(), &cap);
    let cyl = ShapeSpec::Cylinder {
        center: [0.0, 0.0, 0.0],
        axis: [0.0, 0.0, 1.0],
        radius: 0.002,
        length: 0.01,
    };
    check(&mesh(&cyl, 32).unwrap(), &cyl);
    let bx = ShapeSpec::Box {
        center: [0.0; 3],
        half_extents: [0.01, 0.02, 0.03],
        axes: None,
    };
    check(&mesh(&bx, 8).unwrap(), &bx);
}

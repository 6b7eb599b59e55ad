//! Decks as users bring them: what palpa reads, what it warns about, and what it refuses, each
//! message naming the file, the line and the field.

use lsdyna::{read_deck, ReadOptions, Units};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn fails(p: &Path, opts: &ReadOptions) -> lsdyna::DeckError {
    match read_deck(p, opts) {
        Err(e) => e,
        Ok(_) => panic!("{} should not read", p.display()),
    }
}

fn kg_mm_ms() -> ReadOptions {
    ReadOptions {
        units: Some(Units::parse("kg-mm-ms").unwrap()),
        ..Default::default()
    }
}

/// A 2 x 1 x 1 block of two hexahedra (mm), part 1.
const MESH: &str = "*NODE
       1             0.0             0.0             0.0
       2            10.0             0.0             0.0
       3            20.0             0.0             0.0
       4             0.0            10.0             0.0
       5            10.0            10.0             0.0
       6            20.0            10.0             0.0
       7             0.0             0.0            10.0
       8            10.0             0.0            10.0
       9            20.0             0.0            10.0
      10             0.0            10.0            10.0
      11            10.0            10.0            10.0
      12            20.0            10.0            10.0
*ELEMENT_SOLID
       1       1       1       2       5       4       7       8      11      10
       2       1       2       3       6       5       8       9      12      11
";

/// An LS-PrePost-style deck: titles, _ID options, output keywords palpa does not write.
fn prepost_deck(extra: &str) -> String {
    format!(
        "*KEYWORD
*TITLE
a block from LS-PrePost
*CONTROL_TERMINATION
$#  endtim    endcyc     dtmin    endeng    endmas     nosol
      10.0         0       0.0       0.0       0.0         0
*CONTROL_TIMESTEP
$#  dtinit    tssfac      isdo    tslimt     dt2ms      lctm     erode     ms1st
       0.0       0.9         0       0.0       0.0         0         0         0
*CONTROL_ENERGY
$#    hgen      rwen    slnten     rylen
         2         2         2         2
*DATABASE_BINARY_D3PLOT
$#      dt      lcdt      beam     npltc    psetid
       1.0         0         0         0         0
*DATABASE_EXTENT_BINARY
         0         0         3         1         0         0         0         0
*DATABASE_MATSUM
       0.1
*PART
$#                                                                         title
block
$#     pid     secid       mid     eosid      hgid      grav    adpopt      tmid
         1         1         1         0         0         0         0         0
*SECTION_SOLID_TITLE
one point
$#   secid    elform       aet
         1         1         0
*MAT_ELASTIC_TITLE
steel-like rubber
$#     mid        ro         e        pr        da        db  not used
         1    1.0e-6    1.0e-3       0.3       0.0       0.0       0.0
*SET_NODE_LIST_TITLE
base
$#     sid       da1       da2       da3       da4    solver
         1       0.0       0.0       0.0       0.0MECH
$#    nid1      nid2      nid3      nid4      nid5      nid6      nid7      nid8
         1         2         3         4         5         6
*BOUNDARY_SPC_SET_ID
$#      id                                                               heading
         1base fixed
$#    nsid       cid      dofx      dofy      dofz     dofrx     dofry     dofrz
         1         0         1         1         1         0         0         0
{extra}{MESH}*END
"
    )
}

#[test]
fn a_prepost_deck_reads_with_warnings_for_output_only_keywords() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "prepost.k", &prepost_deck(""));
    let (def, report) = read_deck(&p, &kg_mm_ms()).unwrap();
    assert_eq!(def.title, "a block from LS-PrePost");
    assert_eq!(def.mesh.elements.len(), 2);
    assert_eq!(def.mesh.part_names, ["block"]);
    assert_eq!(def.end_time, 0.01);
    assert_eq!(def.mesh.node_sets["base"].len(), 6);
    assert_eq!(def.setup.constraints.len(), 3);
    assert_eq!(def.setup.output.vtk_interval, Some(1e-3));
    let w = report.warnings.join("\n");
    for k in [
        "CONTROL_ENERGY",
        "DATABASE_EXTENT_BINARY",
        "DATABASE_MATSUM",
    ] {
        assert!(w.contains(k) && w.contains("prepost.k:"), "{w}");
    }
}

#[test]
fn no_units_is_refused_with_how_to_give_them() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "nounits.k", &prepost_deck(""));
    let e = fails(&p, &ReadOptions::default()).to_string();
    assert!(
        e.contains("nounits.k") && e.contains("--units") && e.contains("*CONTROL_UNITS"),
        "{e}"
    );
    // *CONTROL_UNITS in the deck is enough; a different --units is a conflict.
    let p = write(
        dir.path(),
        "units.k",
        &prepost_deck("*CONTROL_UNITS\nmm        ms        kg\n"),
    );
    assert!(read_deck(&p, &ReadOptions::default()).is_ok());
    let opts = ReadOptions {
        units: Some(Units::parse("t-mm-s").unwrap()),
        ..Default::default()
    };
    let e = fails(&p, &opts).to_string();
    assert!(
        e.contains("units.k:") && e.contains("kg-mm-ms") && e.contains("t-mm-s"),
        "{e}"
    );
}

/// Every problem is listed, each with file:line and the keyword or field.
#[test]
fn what_would_change_the_physics_is_an_error_naming_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "unknown",
            "*CONSTRAINED_NODAL_RIGID_BODY\n         1\n",
            &["unknown.k:", "*CONSTRAINED_NODAL_RIGID_BODY", "would change the model", "merge the nodes"],
        ),
        (
            "mat057",
            "*MAT_LOW_DENSITY_FOAM\n         9    1.0e-7\n",
            &["mat057.k:", "*MAT_LOW_DENSITY_FOAM", "*MAT_OGDEN_RUBBER"],
        ),
        (
            "rate",
            "*MAT_PIECEWISE_LINEAR_PLASTICITY\n         7    1.0e-6      0.04      0.45    0.0018\n      40.0       5.0\n\n\n",
            &["rate.k:", "field C (columns 1-10)", "strain-rate"],
        ),
        (
            "badnum",
            "*DAMPING_GLOBAL\n         0    0.0x02\n",
            &["badnum.k:", "*DAMPING_GLOBAL, field VALDMP (columns 11-20)", "`0.0x02` is not a number"],
        ),
        (
            "tab",
            "*DAMPING_GLOBAL\n0\t0.02\n",
            &["tab.k:", "tab character"],
        ),
        (
            "param",
            "*PARAMETER_EXPRESSION\nR rho     1.0e-6*1.0\n",
            &["param.k:", "*PARAMETER_EXPRESSION", "expressions"],
        ),
        (
            "mpc",
            "*BOUNDARY_SPC_SET_BIRTH_DEATH\n         1\n",
            &["mpc.k:", "*BOUNDARY_SPC_SET_BIRTH_DEATH", "*BOUNDARY_SPC_NODE"],
        ),
    ];
    for (name, extra, expect) in cases {
        let p = write(dir.path(), &format!("{name}.k"), &prepost_deck(extra));
        let e = fails(&p, &kg_mm_ms()).to_string();
        for x in *expect {
            assert!(e.contains(x), "{name}: `{x}` missing in:\n{e}");
        }
    }
    // Two problems at once are both listed.
    let p = write(
        dir.path(),
        "two.k",
        &prepost_deck("*CONSTRAINED_EXTRA_NODES_SET\n*RIGIDWALL_PLANAR\n"),
    );
    let e = fails(&p, &kg_mm_ms());
    assert_eq!(e.errors.len(), 2, "{e}");
}

#[test]
fn a_degenerate_or_inverted_element_or_a_missing_node_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let tet = prepost_deck("").replace(
        "       2       1       2       3       6       5       8       9      12      11",
        "       2       1       2       3       6       6       8       8       8       8",
    );
    let e = fails(&write(dir.path(), "tet.k", &tet), &kg_mm_ms()).to_string();
    assert!(
        e.contains("tet.k:") && e.contains("*ELEMENT_SOLID 2") && e.contains("degenerate"),
        "{e}"
    );
    let inv = prepost_deck("").replace(
        "       1       1       1       2       5       4       7       8      11      10",
        "       1       1       7       8      11      10       1       2       5       4",
    );
    let e = fails(&write(dir.path(), "inv.k", &inv), &kg_mm_ms()).to_string();
    assert!(
        e.contains("inv.k:") && e.contains("*ELEMENT_SOLID 1") && e.contains("inverted"),
        "{e}"
    );
    let missing = prepost_deck("").replace("      12            20.0", "      99            20.0");
    let e = fails(&write(dir.path(), "miss.k", &missing), &kg_mm_ms()).to_string();
    assert!(e.contains("miss.k:") && e.contains("node 12"), "{e}");
    let e = fails(&dir.path().join("nothere.k"), &kg_mm_ms()).to_string();
    assert!(e.contains("nothere.k") && e.contains("cannot read"), "{e}");
}

#[test]
fn free_format_long_format_and_includes_read_the_same_block() {
    let dir = tempfile::tempdir().unwrap();
    let base = read_deck(&write(dir.path(), "base.k", &prepost_deck("")), &kg_mm_ms())
        .unwrap()
        .0;
    // The mesh in an include file, written in free format.
    let free_mesh: String = MESH
        .lines()
        .map(|l| {
            if l.starts_with('*') {
                l.to_string()
            } else {
                l.split_whitespace().collect::<Vec<_>>().join(",")
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    write(
        dir.path(),
        "mesh.k",
        &format!("*KEYWORD\n{free_mesh}\n*END\n"),
    );
    let inc = prepost_deck("").replace(MESH, "*INCLUDE\nmesh.k\n");
    let d = read_deck(&write(dir.path(), "inc.k", &inc), &kg_mm_ms())
        .unwrap()
        .0;
    assert_eq!(d.mesh.nodes, base.mesh.nodes);
    assert_eq!(d.mesh.elements, base.mesh.elements);
}

/// `*PARAMETER`: `&NAME` and `-&NAME` read as the values (the same scene as the literal deck);
/// an undefined name and a second definition are errors naming the field and both lines.
#[test]
fn parameters_read_as_their_values() {
    let dir = tempfile::tempdir().unwrap();
    let base = read_deck(&write(dir.path(), "base.k", &prepost_deck("")), &kg_mm_ms())
        .unwrap()
        .0;
    let with = prepost_deck("")
        .replace(
            "*CONTROL_TERMINATION",
            "*PARAMETER\nR   YOUNG     1.0e-3R   TEND      -10.0\n*PARAMETER\nI NONE,0\n*CONTROL_TERMINATION",
        )
        .replace("      10.0         0", "    -&tend     &NONE")
        .replace("    1.0e-6    1.0e-3", "    1.0e-6    &YOUNG");
    let d = read_deck(&write(dir.path(), "par.k", &with), &kg_mm_ms())
        .unwrap()
        .0;
    assert_eq!(d.end_time, base.end_time);
    assert_eq!(d.mesh.nodes, base.mesh.nodes);
    let show = |s: &scene::def::SceneDef| format!("{:?}", s.setup.parts[0].spec);
    assert_eq!(show(&d), show(&base));
    let undefined = with.replace("    1.0e-6    &YOUNG", "    1.0e-6   &YOUNGS");
    let e = fails(&write(dir.path(), "undef.k", &undefined), &kg_mm_ms())
        .errors
        .join("\n");
    assert!(
        e.contains("undef.k:")
            && e.contains("field E (columns 21-30)")
            && e.contains("`&YOUNGS` is not defined"),
        "{e}"
    );
    let twice = with.replace("I NONE,0", "R YOUNG,2.0");
    let e = fails(&write(dir.path(), "twice.k", &twice), &kg_mm_ms())
        .errors
        .join("\n");
    assert!(
        e.contains("twice.k:7: *PARAMETER: parameter `YOUNG` is defined again (first at ")
            && e.contains("twice.k:5)"),
        "{e}"
    );
}

/// A rigid punch meshed with one solid, moved along z with CMO = 0 (LS-DYNA leaves its other
/// degrees of freedom free): palpa reads it as an indenter, holds them, and says so.
#[test]
fn a_rigid_solid_with_free_rotations_reads_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let punch = "*PART
punch
         2         1         2
*MAT_RIGID
         2    7.8e-6     210.0       0.3
*NODE
     101             5.0             2.0            10.5
     102            15.0             2.0            10.5
     103            15.0             8.0            10.5
     104             5.0             8.0            10.5
     105             5.0             2.0            15.0
     106            15.0             2.0            15.0
     107            15.0             8.0            15.0
     108             5.0             8.0            15.0
*ELEMENT_SOLID
     101       2     101     102     103     104     105     106     107     108
*DEFINE_CURVE
         7
                 0.0                 0.0
                10.0                -1.0
*BOUNDARY_PRESCRIBED_MOTION_RIGID
         2         3         2         7
*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE
         1         2         3         3
";
    let p = write(dir.path(), "punch.k", &prepost_deck(punch));
    let (def, report) = read_deck(&p, &kg_mm_ms()).unwrap();
    assert_eq!(
        def.mesh.part_names,
        ["block"],
        "the rigid part is no mesh part"
    );
    let ind = &def.setup.contact.as_ref().unwrap().indenters;
    assert_eq!(ind.len(), 1);
    assert_eq!(ind[0].spec.direction, [0.0, 0.0, -1.0]);
    let w = report.warnings.join("\n");
    assert!(
        w.contains("punch.k:")
            && w.contains("its translation along x and y and its rotations")
            && w.contains("CMO = 1, CON1 = 4, CON2 = 7"),
        "{w}"
    );
}

#[test]
fn hourglass_types_6_and_7_read_as_the_physical_form_and_8_is_refused() {
    use solver::element::{Formulation, HourglassForm};
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "ihq6.k",
        &prepost_deck("*CONTROL_HOURGLASS\n         6       1.0\n"),
    );
    let (def, report) = read_deck(&p, &kg_mm_ms()).unwrap();
    match def.setup.parts[0].formulation {
        Formulation::OnePoint(h) => {
            assert_eq!(h.form, HourglassForm::Physical);
            assert_eq!(h.coefficient, 1.0);
        }
        f => panic!("{f:?}"),
    }
    let w = report.warnings.join("\n");
    assert!(w.contains("IHQ = 6") && w.contains("physical"), "{w}");
    let p = write(
        dir.path(),
        "ihq7.k",
        &prepost_deck("*CONTROL_HOURGLASS\n         7       1.0\n"),
    );
    let (def, _) = read_deck(&p, &kg_mm_ms()).unwrap();
    assert!(matches!(
        def.setup.parts[0].formulation,
        Formulation::OnePoint(h) if h.form == HourglassForm::Physical
    ));
    let p = write(
        dir.path(),
        "ihq8.k",
        &prepost_deck("*CONTROL_HOURGLASS\n         8       1.0\n"),
    );
    let e = fails(&p, &kg_mm_ms()).to_string();
    assert!(e.contains("IHQ = 8") && e.contains("ihq8.k"), "{e}");
}

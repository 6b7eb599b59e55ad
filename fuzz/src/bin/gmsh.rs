//! afl.rs target `gmsh`: [`palpa_fuzz::gmsh`]. Built by `cargo afl build` it is the fuzz
//! target; a plain build replays the files named on its command line.

// `fuzz_nohook`: a panic that palpa itself catches (vtkio's, in the VTU reader) is not a
// crash; any other panic still is.
#[cfg(fuzzing)]
fn main() {
    afl::fuzz_nohook!(|data: &[u8]| palpa_fuzz::gmsh(data));
}

#[cfg(not(fuzzing))]
fn main() {
    palpa_fuzz::replay_args("gmsh", palpa_fuzz::gmsh);
}

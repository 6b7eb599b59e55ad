//! afl.rs target `nifti`: [`palpa_fuzz::nifti`]. Built by `cargo afl build` it is the fuzz
//! target; a plain build replays the files named on its command line.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| palpa_fuzz::nifti(data));
}

#[cfg(not(fuzzing))]
fn main() {
    palpa_fuzz::replay_args("nifti", palpa_fuzz::nifti);
}

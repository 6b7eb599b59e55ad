//! afl.rs target `units`: [`palpa_fuzz::units`]. Built by `cargo afl build` it is the fuzz
//! target; a plain build replays the files named on its command line.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| palpa_fuzz::units(data));
}

#[cfg(not(fuzzing))]
fn main() {
    palpa_fuzz::replay_args("units", palpa_fuzz::units);
}

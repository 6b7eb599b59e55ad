//! afl.rs target `serve_message`: [`palpa_fuzz::serve_message`]. Built by `cargo afl build` it is the fuzz
//! target; a plain build replays the files named on its command line.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| palpa_fuzz::serve_message(data));
}

#[cfg(not(fuzzing))]
fn main() {
    palpa_fuzz::replay_args("serve_message", palpa_fuzz::serve_message);
}

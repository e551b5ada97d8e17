//! `data-gen`: deterministic synthetic data with exact ground truth for subdyn.
//!
//! Not built yet: the data-gen issue fills this binary. It exits non-zero so
//! nobody mistakes it for a working generator.

fn main() {
    eprintln!("data-gen: not implemented yet (see the data-gen issue); nothing was written");
    std::process::exit(2);
}

//! The command-line interface: one file per verb, shared helpers in `common`.

mod app;
mod bench;
mod bench_closest;
mod bench_distance;
mod common;
mod compare;
mod ffd;
mod fit;
mod info;
mod lattice;
mod limit;
mod mesh_stats;
mod options;
mod progress;
mod render;
mod subdivide;

pub use app::run;

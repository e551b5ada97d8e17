//! The command-line interface: one file per verb, shared helpers in `common`.

mod app;
mod bench;
mod bench_closest;
mod bench_distance;
mod bench_ffd;
mod bench_fit;
mod bench_recover;
mod bench_sculpt;
mod common;
mod compare;
mod ffd;
mod finetune;
mod finetune_curve;
mod finetune_surface;
mod fit;
mod info;
mod info_lattice;
mod info_volume;
mod lattice;
mod limit;
mod memory;
mod mesh_stats;
mod options;
mod progress;
mod recover;
mod render;
mod render_lattice;
mod sculpt;
mod sculpt_demo;
mod sculpt_script;
mod signals;
mod subdivide;
mod subdivide_scheme;
mod threads;

pub use app::run;

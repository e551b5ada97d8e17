//! The connected components of a thresholded volume and the points where
//! its interpolant crosses the level around them (marching cubes' vertices),
//! for the automatic cage of [`super::component_cage`].

use std::collections::VecDeque;

use crate::fit::init::voxels::FACE_NEIGHBOURS;
use crate::math::{Point3, Real};
use crate::volume::Volume;

/// The 6-connected components of the voxels inside the object: every
/// voxel's label (`u32::MAX` outside), each component's voxel count and
/// its box of voxel indices.
#[allow(clippy::type_complexity)]
pub(super) fn components(
    volume: &Volume,
    level: Real,
    bright_inside: bool,
) -> (Vec<u32>, Vec<usize>, Vec<([usize; 3], [usize; 3])>) {
    let inside = |v: f32| {
        let v = v as Real;
        if bright_inside { v > level } else { v < level }
    };
    let n = volume.data().len();
    let mut label = vec![u32::MAX; n];
    let mut sizes: Vec<usize> = Vec::new();
    let mut boxes: Vec<([usize; 3], [usize; 3])> = Vec::new();
    let mut queue = VecDeque::new();
    for start in 0..n {
        if label[start] != u32::MAX || !inside(volume.data()[start]) {
            continue;
        }
        let id = sizes.len() as u32;
        label[start] = id;
        queue.push_back(start);
        let (mut size, mut lo, mut hi) = (0, volume.voxel(start), volume.voxel(start));
        while let Some(i) = queue.pop_front() {
            size += 1;
            let c = volume.voxel(i);
            for a in 0..3 {
                lo[a] = lo[a].min(c[a]);
                hi[a] = hi[a].max(c[a]);
            }
            for j in FACE_NEIGHBOURS
                .iter()
                .filter_map(|&d| volume.offset_index(c, d))
            {
                if label[j] == u32::MAX && inside(volume.data()[j]) {
                    label[j] = id;
                    queue.push_back(j);
                }
            }
        }
        sizes.push(size);
        boxes.push((lo, hi));
    }
    (label, sizes, boxes)
}

/// The points where the linear interpolant of `volume` crosses `level` on
/// the edges from a voxel `i` with `take(i)` to a face neighbour with
/// another `label`, which is not inside (components are maximal), in voxel
/// order.
pub(super) fn iso_crossings(
    volume: &Volume,
    label: &[u32],
    take: impl Fn(usize) -> bool,
    level: Real,
) -> Vec<Point3> {
    let data = volume.data();
    let mut out = Vec::new();
    for i in (0..label.len()).filter(|&i| take(i)) {
        let chosen = label[i];
        let c = volume.voxel(i);
        let a = data[i] as Real;
        for d in FACE_NEIGHBOURS {
            let Some(j) = volume.offset_index(c, d) else {
                continue;
            };
            if label[j] == chosen {
                continue;
            }
            let b = data[j] as Real;
            let t = if a == b {
                0.5
            } else {
                ((a - level) / (a - b)).clamp(0.0, 1.0)
            };
            out.push(volume.world([0, 1, 2].map(|k| c[k] as Real + t * d[k] as Real)));
        }
    }
    out
}

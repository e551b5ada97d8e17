//! Closing objects cut by the volume's box: one layer of "outside" samples
//! around the grid, placed so the iso-surface closes on the box faces.

use crate::error::{Error, Result};
use std::f64::consts::FRAC_1_SQRT_2;

use crate::math::{Real, newell_normal};
use crate::mesh::PolyMesh;
use crate::volume::Volume;

/// `volume` with one more sample on every side of every axis (dims `n + 2`,
/// the origin moved one step back along each index axis), so that an object
/// cut by the box closes there, as marching cubes on a padded volume does.
///
/// A pad sample next to a border sample `v` is `min(v, 2L − v)` for a bright
/// object (`max` for a dark one), `L` the inside level: a border sample
/// outside the object is copied (the clamped extension the samplers use, so
/// nothing changes where the object does not touch the box), and one inside
/// is mirrored about `L`. The trilinear interpolant between `v` and its pad
/// `2L − v` crosses `L` half-way, so the cap lies on the box face itself, half a
/// voxel beyond the outermost sample centres (index `−½` and `n − ½`), whatever
/// the contrast. Pad samples touching several faces take the mirror of the
/// nearest border sample (the index clamped to the grid).
pub fn padded_at_level(volume: &Volume, level: Real, bright_inside: bool) -> Result<Volume> {
    let [nx, ny, nz] = volume.dims();
    let dims = [nx + 2, ny + 2, nz + 2];
    let data = volume.data();
    let outside = |v: f32| -> f32 {
        let mirrored = (2.0 * level - v as Real) as f32;
        if bright_inside {
            v.min(mirrored)
        } else {
            v.max(mirrored)
        }
    };
    let mut out = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        let (kk, kb) = clamped(k, nz);
        for j in 0..dims[1] {
            let (jj, jb) = clamped(j, ny);
            let row = nx * (jj + ny * kk);
            if !(kb || jb) {
                out.push(outside(data[row]));
                out.extend_from_slice(&data[row..row + nx]);
                out.push(outside(data[row + nx - 1]));
            } else {
                out.extend((0..dims[0]).map(|i| outside(data[row + clamped(i, nx).0])));
            }
        }
    }
    let origin = volume.world([-1.0, -1.0, -1.0]);
    Volume::with_affine(dims, out, *volume.linear(), origin)
}

/// The original index of padded index `i` on an axis of `n` samples, clamped
/// to the grid, and whether `i` is a pad sample.
fn clamped(i: usize, n: usize) -> (usize, bool) {
    if i == 0 {
        (0, true)
    } else if i > n {
        (n - 1, true)
    } else {
        (i - 1, false)
    }
}

/// `control` (the closed result on the padded grid `padded`) opened where
/// the box cut the object (`--open-at-box`): every face whose vertices all
/// lie on one face of the input's box (within 1.5 voxels of it, or beyond)
/// and that faces out through it is removed, with the vertices no face
/// keeps. The vertices of the rim are moved onto that face (the cage lies
/// up to a voxel or two outside the surface), so the limit surface's
/// boundary, the B-spline of the rim (edge-and-corner rule), lies in it.
/// Errors when no face is removed (the object does not touch the box) or
/// every face is.
pub fn opened_at_box(control: &PolyMesh, padded: &Volume) -> Result<PolyMesh> {
    let dims = padded.dims();
    let index: Vec<[Real; 3]> = control
        .positions
        .iter()
        .map(|p| padded.continuous_index(p))
        .collect();
    // Input samples are padded indices 1 ..= n − 2; its box faces at ½ and
    // n − 1.5. The closed result's cap lies on the face, its control points
    // up to a voxel or two inside or beyond it: a face is a cap when its
    // vertices are within 1.5 voxels inside the face (index ≤ 2 or
    // ≥ n − 3) or beyond, and it faces out through the box face (normal
    // within 45° of the outward axis).
    let on = |v: u32, axis: usize, high: bool| {
        let c = index[v as usize][axis];
        if high {
            c >= dims[axis] as Real - 3.0
        } else {
            c <= 2.0
        }
    };
    let origin = padded.world([0.0; 3]);
    let outward = |axis: usize, high: bool| {
        let mut e = [0.0; 3];
        e[axis] = if high { 1.0 } else { -1.0 };
        (padded.world(e) - origin).normalize()
    };
    let faces_out = |f: &[u32], axis: usize, high: bool| {
        let n = newell_normal(&control.positions, f);
        n.dot(&outward(axis, high)) >= FRAC_1_SQRT_2 * n.norm()
    };
    let mut cap: Vec<Option<(usize, bool)>> = control
        .faces()
        .map(|f| {
            (0..3)
                .flat_map(|axis| [(axis, false), (axis, true)])
                .find(|&(axis, high)| {
                    f.iter().all(|&v| on(v, axis, high)) && faces_out(f, axis, high)
                })
        })
        .collect();
    // Stray cap faces (a bump that tilts a wall face near the rim towards
    // the box face) stay: only connected groups of cap faces of at least a
    // tenth of the largest group's size are removed.
    let capped: Vec<bool> = cap.iter().map(Option::is_some).collect();
    let groups = edge_components(control, &capped);
    let group_sizes = part_sizes(&groups);
    let big = group_sizes.iter().copied().max().unwrap_or(0);
    for (c, g) in cap.iter_mut().zip(&groups) {
        if g.is_some_and(|g| 10 * group_sizes[g] < big) {
            *c = None;
        }
    }
    // Islands of kept faces inside the opening (a face the noise tilted
    // away from the box face) go with the cap: only the largest part of the
    // surface is kept.
    let kept: Vec<bool> = cap.iter().map(Option::is_none).collect();
    let part = edge_components(control, &kept);
    let sizes = part_sizes(&part);
    let largest = (0..sizes.len()).max_by_key(|&p| (sizes[p], std::cmp::Reverse(p)));
    for (f, face) in control.faces().enumerate() {
        if part[f].is_some() && part[f] != largest {
            cap[f] = (0..3)
                .flat_map(|axis| [(axis, false), (axis, true)])
                .find(|&(axis, high)| face.iter().all(|&v| on(v, axis, high)));
        }
    }
    keep_manifold(control, &mut cap);
    let mut keep = Vec::new();
    // Per vertex and axis, the index of the box face of a removed face.
    let mut face_of = vec![[None::<Real>; 3]; control.num_vertices()];
    for (f, c) in control.faces().zip(&cap) {
        match *c {
            Some((axis, high)) => {
                let at = if high { dims[axis] as Real - 1.5 } else { 0.5 };
                for &v in f {
                    face_of[v as usize][axis] = Some(at);
                }
            }
            None => keep.push(f.to_vec()),
        }
    }
    if keep.len() == control.num_faces() {
        return Err(Error::input(
            "opening at the box: the object does not reach the volume's box, nothing to open",
        ));
    }
    if keep.is_empty() {
        return Err(Error::input(
            "opening at the box: the whole surface lies on the volume's box",
        ));
    }
    let mut new_index = vec![u32::MAX; control.num_vertices()];
    let mut positions = Vec::new();
    for f in &mut keep {
        for v in f.iter_mut() {
            if new_index[*v as usize] == u32::MAX {
                new_index[*v as usize] = positions.len() as u32;
                let mut c = index[*v as usize];
                for (c, at) in c.iter_mut().zip(face_of[*v as usize]) {
                    *c = at.unwrap_or(*c);
                }
                positions.push(if face_of[*v as usize] == [None; 3] {
                    control.positions[*v as usize]
                } else {
                    padded.world(c)
                });
            }
            *v = new_index[*v as usize];
        }
    }
    PolyMesh::from_faces(positions, &keep)
}

/// Puts back (sets to `None`) cap faces of `cap` until no vertex's kept
/// faces form more than one fan: removing the caps can leave a vertex
/// where two parts of the surface meet at a point only (a bow tie), which
/// is not a manifold; all faces round such a vertex are kept.
fn keep_manifold(control: &PolyMesh, cap: &mut [Option<(usize, bool)>]) {
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); control.num_vertices()];
    for (f, face) in control.faces().enumerate() {
        for &v in face {
            around[v as usize].push(f as u32);
        }
    }
    // The neighbours of `v` along face `f`'s sides (the previous and the
    // next corner).
    let sides = |f: u32, v: u32| {
        let face = control.face(f as usize);
        let i = face.iter().position(|&u| u == v).unwrap_or(0);
        let n = face.len();
        [face[(i + n - 1) % n], face[(i + 1) % n]]
    };
    loop {
        let mut changed = false;
        for (v, faces) in around.iter().enumerate() {
            let kept: Vec<u32> = faces
                .iter()
                .copied()
                .filter(|&f| cap[f as usize].is_none())
                .collect();
            if kept.len() < 2 || kept.len() == faces.len() {
                continue;
            }
            // Fans: kept faces joined through a shared side at `v`.
            let mut fan: Vec<usize> = (0..kept.len()).collect();
            let root = |fan: &mut Vec<usize>, mut i: usize| {
                while fan[i] != i {
                    fan[i] = fan[fan[i]];
                    i = fan[i];
                }
                i
            };
            for a in 0..kept.len() {
                for b in a + 1..kept.len() {
                    let (sa, sb) = (sides(kept[a], v as u32), sides(kept[b], v as u32));
                    if sa.iter().any(|w| sb.contains(w)) {
                        let (ra, rb) = (root(&mut fan, a), root(&mut fan, b));
                        fan[ra] = rb;
                    }
                }
            }
            let fans = (0..kept.len()).filter(|&i| root(&mut fan, i) == i).count();
            if fans > 1 {
                for &f in faces {
                    cap[f as usize] = None;
                }
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
}

/// How many faces each part of [`edge_components`] has.
fn part_sizes(part: &[Option<usize>]) -> Vec<usize> {
    let mut sizes = vec![0usize; part.iter().flatten().max().map_or(0, |&m| m + 1)];
    for &p in part.iter().flatten() {
        sizes[p] += 1;
    }
    sizes
}

/// The connected parts (through shared edges) of the faces of `control`
/// that are `member`s, numbered from 0 in face order (`None` for the
/// others).
fn edge_components(control: &PolyMesh, member: &[bool]) -> Vec<Option<usize>> {
    let mut by_edge: std::collections::HashMap<(u32, u32), Vec<usize>> =
        std::collections::HashMap::new();
    for (f, face) in control.faces().enumerate() {
        if !member[f] {
            continue;
        }
        for i in 0..face.len() {
            let (a, b) = (face[i], face[(i + 1) % face.len()]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut part: Vec<Option<usize>> = vec![None; control.num_faces()];
    let mut next = 0;
    for start in 0..control.num_faces() {
        if !member[start] || part[start].is_some() {
            continue;
        }
        part[start] = Some(next);
        let mut stack = vec![start];
        while let Some(f) = stack.pop() {
            let face = control.face(f);
            for i in 0..face.len() {
                let (a, b) = (face[i], face[(i + 1) % face.len()]);
                for &g in &by_edge[&(a.min(b), a.max(b))] {
                    if part[g].is_none() {
                        part[g] = Some(next);
                        stack.push(g);
                    }
                }
            }
        }
        next += 1;
    }
    part
}

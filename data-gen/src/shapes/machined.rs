//! Machined parts with truly sharp edges, thin walls, thin legs and narrow
//! gaps, built from axis-aligned boxes ([`cuboid_solid_mesh`]): a plate with
//! a slot (genus 1), an L-bracket with holes and a slot (genus 4) and a chair
//! with thin legs and a slatted back (genus 5). Lengths in model units; the
//! sidecar records every box ([`formula`]).

use subdyn::error::Result;
use subdyn::mesh::PolyMesh;

use super::cuboids::{Cuboid, CuboidSolid, cuboid_solid_mesh};

/// A 2 × 1.2 × 0.1 plate with a 1 × 0.16 through slot.
pub const PLATE: CuboidSolid = CuboidSolid {
    solid: &[Cuboid::new([-1.0, -0.6, 0.0], [1.0, 0.6, 0.1])],
    holes: &[Cuboid::new([-0.5, -0.08, -1.0], [0.5, 0.08, 1.0])],
};

/// An L-bracket: a 2 × 1 × 0.15 base and a 2 × 0.15 × 1 flange along its
/// back edge; two 0.3 × 0.3 holes and a 0.5 × 0.15 slot through the base, a
/// 0.3 × 0.3 hole through the flange.
pub const BRACKET: CuboidSolid = CuboidSolid {
    solid: &[
        Cuboid::new([-1.0, 0.0, 0.0], [1.0, 1.0, 0.15]),
        Cuboid::new([-1.0, 0.0, 0.0], [1.0, 0.15, 1.0]),
    ],
    holes: &[
        Cuboid::new([-0.7, 0.4, -1.0], [-0.4, 0.7, 1.0]),
        Cuboid::new([0.4, 0.4, -1.0], [0.7, 0.7, 1.0]),
        Cuboid::new([-0.25, 0.55, -1.0], [0.25, 0.7, 1.0]),
        Cuboid::new([-0.15, -1.0, 0.45], [0.15, 1.0, 0.75]),
    ],
};

/// A chair: a 1 × 1 × 0.08 seat at height 0.9 on four 0.08 × 0.08 legs, a
/// back of two posts, a top rail and four 0.08-wide slats with 0.1–0.11 gaps.
pub const CHAIR: CuboidSolid = CuboidSolid {
    solid: &[
        // Legs.
        Cuboid::new([-0.5, -0.5, 0.0], [-0.42, -0.42, 0.9]),
        Cuboid::new([0.42, -0.5, 0.0], [0.5, -0.42, 0.9]),
        Cuboid::new([-0.5, 0.42, 0.0], [-0.42, 0.5, 0.9]),
        Cuboid::new([0.42, 0.42, 0.0], [0.5, 0.5, 0.9]),
        // Seat.
        Cuboid::new([-0.5, -0.5, 0.9], [0.5, 0.5, 0.98]),
        // Back posts and top rail.
        Cuboid::new([-0.5, 0.42, 0.98], [-0.42, 0.5, 1.9]),
        Cuboid::new([0.42, 0.42, 0.98], [0.5, 0.5, 1.9]),
        Cuboid::new([-0.42, 0.42, 1.7], [0.42, 0.5, 1.9]),
        // Slats.
        Cuboid::new([-0.31, 0.44, 0.98], [-0.23, 0.48, 1.7]),
        Cuboid::new([-0.13, 0.44, 0.98], [-0.05, 0.48, 1.7]),
        Cuboid::new([0.05, 0.44, 0.98], [0.13, 0.48, 1.7]),
        Cuboid::new([0.23, 0.44, 0.98], [0.31, 0.48, 1.7]),
    ],
    holes: &[],
};

/// The plate's mesh, `resolution` grid steps along its longest side.
pub fn plate(resolution: usize) -> Result<PolyMesh> {
    cuboid_solid_mesh(&PLATE, resolution)
}

/// The bracket's mesh, `resolution` grid steps along its longest side.
pub fn bracket(resolution: usize) -> Result<PolyMesh> {
    cuboid_solid_mesh(&BRACKET, resolution)
}

/// The chair's mesh, `resolution` grid steps along its longest side.
pub fn chair(resolution: usize) -> Result<PolyMesh> {
    cuboid_solid_mesh(&CHAIR, resolution)
}

/// The boxes of `solid`, for sidecars.
pub fn formula(solid: &CuboidSolid) -> String {
    let list = |boxes: &[Cuboid]| {
        boxes
            .iter()
            .map(|b| {
                format!(
                    "[{}, {}, {}]..[{}, {}, {}]",
                    b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(
        "union of boxes {} minus union of boxes [{}]; f = max(min_i box_i(p), -min_j hole_j(p)), box(p) the exact box distance; inside f < 0; edges sharp (not blended)",
        list(solid.solid),
        list(solid.holes)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::mesh_topology;

    fn check(solid: &CuboidSolid, mesh: &PolyMesh, genus: i64) {
        let t = mesh_topology(mesh);
        assert!(t.closed_manifold, "{t:?}");
        assert_eq!(t.genus, Some(genus), "{t:?}");
        assert!(2 * mesh.num_faces() < 50_000, "{} quads", mesh.num_faces());
        for p in &mesh.positions {
            assert!(solid.field(p).abs() < 1e-14, "{p:?}");
        }
    }

    /// A sharp edge: the two faces at it meet at 90°, i.e. some mesh edge has
    /// faces whose normals are perpendicular (a blend would leave every
    /// dihedral angle near 180° at this resolution).
    fn has_right_angle_edges(mesh: &PolyMesh) -> bool {
        let normal = |f: &[u32]| {
            let p = |i: usize| mesh.positions[f[i] as usize];
            (p(1) - p(0)).cross(&(p(2) - p(0))).normalize()
        };
        let mut by_edge = std::collections::HashMap::new();
        let mut right = 0;
        for f in mesh.faces() {
            for i in 0..f.len() {
                let (a, b) = (f[i], f[(i + 1) % f.len()]);
                if let Some(m) = by_edge.insert((a.min(b), a.max(b)), normal(f))
                    && m.dot(&normal(f)).abs() < 1e-12
                {
                    right += 1;
                }
            }
        }
        right > 0
    }

    #[test]
    fn plate_is_a_closed_genus_one_solid_with_sharp_edges() {
        let mesh = plate(100).unwrap();
        check(&PLATE, &mesh, 1);
        assert!(has_right_angle_edges(&mesh));
        // Volume exactly 2 × 1.2 × 0.1 − 1 × 0.16 × 0.1.
        let v = crate::measure::enclosed_volume(&mesh);
        assert!((v - (0.24 - 0.016)).abs() < 1e-12, "{v}");
    }

    #[test]
    fn bracket_has_four_handles() {
        let mesh = bracket(90).unwrap();
        check(&BRACKET, &mesh, 4);
        assert!(has_right_angle_edges(&mesh));
    }

    #[test]
    fn chair_has_five_gaps_in_its_back() {
        let mesh = chair(100).unwrap();
        check(&CHAIR, &mesh, 5);
        assert!(has_right_angle_edges(&mesh));
    }
}

//! Integration tests of `subdyn::topology`: bad connectivity is reported as
//! `Error::Topology` naming the element; boundaries, valences, ordered vertex
//! rings and Euler characteristics on small hand-built meshes.

mod common;

use common::*;
use subdyn::Error;
use subdyn::math::Point3;
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{RefineOptions, Refiner};
use subdyn::topology::{Level, NONE};

/// `n` points on a slightly wavy line (positions do not matter to topology).
fn points(n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| Point3::new(i as f64, (i * i % 7) as f64, (i % 3) as f64))
        .collect()
}

/// A mesh built without validation, as a reader might hand it over.
fn raw_mesh(nv: usize, faces: &[&[u32]]) -> PolyMesh {
    let mut face_offsets = vec![0u32];
    let mut face_vertices = Vec::new();
    for f in faces {
        face_vertices.extend_from_slice(f);
        face_offsets.push(face_vertices.len() as u32);
    }
    PolyMesh {
        positions: points(nv),
        face_offsets,
        face_vertices,
    }
}

/// All integers in a message.
fn numbers_in(msg: &str) -> Vec<u64> {
    msg.split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .filter_map(|s| s.parse().ok())
        .collect()
}

/// Checks that both `Level::from_mesh` and `Refiner::new` reject the mesh
/// with `Error::Topology`, that the message contains `word` and names every
/// number in `ids`; returns the message.
fn expect_topology_error(mesh: &PolyMesh, word: &str, ids: &[u64]) -> String {
    let from_level = Level::from_mesh(mesh).err();
    let from_refiner = Refiner::new(mesh, &RefineOptions::default()).err();
    let mut msg = String::new();
    for (who, err) in [
        ("Level::from_mesh", from_level),
        ("Refiner::new", from_refiner),
    ] {
        match err {
            Some(Error::Topology(m)) => {
                assert!(
                    m.to_lowercase().contains(word),
                    "{who}: message {m:?} does not say {word:?}"
                );
                let nums = numbers_in(&m);
                for id in ids {
                    assert!(nums.contains(id), "{who}: message {m:?} does not name {id}");
                }
                assert!(!m.contains('\n'), "{who}: message {m:?} is not one line");
                msg = m;
            }
            Some(other) => panic!("{who}: expected Error::Topology, got {other:?}"),
            None => panic!("{who}: accepted a mesh with a {word} problem"),
        }
    }
    msg
}

#[test]
fn non_manifold_edge_names_its_vertices() {
    // Three quads share the edge (5, 7).
    let mesh = raw_mesh(
        12,
        &[&[5, 7, 0, 1], &[7, 5, 2, 3], &[5, 7, 4, 6], &[8, 9, 10, 11]],
    );
    expect_topology_error(&mesh, "non-manifold", &[5, 7]);
    // Also through the validating constructor.
    let faces: Vec<Vec<u32>> = vec![vec![5, 7, 0, 1], vec![7, 5, 2, 3], vec![5, 7, 4, 6]];
    let mesh = PolyMesh::from_faces(points(8), &faces).unwrap();
    expect_topology_error(&mesh, "non-manifold", &[5, 7]);
}

#[test]
fn repeated_vertex_in_a_face_is_reported() {
    let mesh = raw_mesh(6, &[&[0, 1, 2, 3], &[3, 2, 4, 2]]);
    expect_topology_error(&mesh, "degenerate", &[1, 2]);
}

#[test]
fn out_of_range_index_is_reported() {
    let faces: Vec<Vec<u32>> = vec![vec![0, 1, 2, 3], vec![3, 2, 9]];
    match PolyMesh::from_faces(points(4), &faces) {
        Err(Error::Topology(m)) => {
            let nums = numbers_in(&m);
            assert!(
                nums.contains(&9) && nums.contains(&1),
                "message {m:?} should name vertex 9 and face 1"
            );
        }
        other => panic!("expected Error::Topology, got {other:?}"),
    }
    let mesh = raw_mesh(4, &[&[0, 1, 2, 3], &[3, 2, 9]]);
    expect_topology_error(&mesh, "vertex", &[9, 1]);
}

#[test]
fn inconsistent_orientation_is_reported() {
    // Both quads run the shared edge 1 -> 4 the same way.
    let mesh = raw_mesh(6, &[&[0, 1, 4, 3], &[1, 4, 5, 2]]);
    let msg = expect_topology_error(&mesh, "orientation", &[1, 4]);
    assert!(
        numbers_in(&msg).contains(&0),
        "message {msg:?} should name the faces 0 and 1"
    );
}

#[test]
fn bow_tie_vertex_is_reported() {
    // Two triangles meeting only at vertex 4.
    let mesh = raw_mesh(5, &[&[0, 1, 4], &[4, 2, 3]]);
    expect_topology_error(&mesh, "non-manifold", &[4]);
    // Two closed fans (tetrahedra) sharing vertex 3: no boundary edge at 3.
    let mesh = raw_mesh(
        7,
        &[
            &[0, 2, 1],
            &[0, 1, 3],
            &[1, 2, 3],
            &[2, 0, 3],
            &[3, 5, 4],
            &[3, 4, 6],
            &[3, 6, 5],
            &[4, 5, 6],
        ],
    );
    expect_topology_error(&mesh, "non-manifold", &[3]);
}

#[test]
fn face_with_two_vertices_is_reported() {
    let faces: Vec<Vec<u32>> = vec![vec![0, 1, 2, 3], vec![2, 1]];
    match PolyMesh::from_faces(points(4), &faces) {
        Err(Error::Topology(m)) => {
            assert!(
                numbers_in(&m).contains(&1),
                "message {m:?} should name face 1"
            )
        }
        other => panic!("expected Error::Topology, got {other:?}"),
    }
    let mesh = raw_mesh(4, &[&[0, 1, 2, 3], &[2, 1]]);
    expect_topology_error(&mesh, "face", &[1]);
}

#[test]
fn bad_crease_is_an_input_error() {
    let cube = subdyn::examples::cube();
    for creases in [vec![(0, 7, 1.0)], vec![(0, 1, -1.0)], vec![(0, 99, 1.0)]] {
        let opts = RefineOptions {
            creases: creases.clone(),
            ..Default::default()
        };
        match Refiner::new(&cube, &opts) {
            Err(Error::Input(m)) => assert!(
                numbers_in(&m).contains(&(creases[0].1 as u64)),
                "message {m:?} should name the crease's vertices"
            ),
            other => panic!("crease {creases:?}: expected Error::Input, got {other:?}"),
        }
    }
}

// ---------------------------------------------------------------------------
// Boundary, valence, rings

#[test]
fn boundary_and_valence_of_small_meshes() {
    let quad = Level::from_mesh(&single_quad()).unwrap();
    assert_eq!(quad.num_edges(), 4);
    for v in 0..4 {
        assert!(quad.is_boundary_vertex(v));
        assert_eq!(quad.valence(v), 2);
    }
    assert!((0..4).all(|e| quad.is_boundary_edge(e)));

    // 3×3 vertex grid: the middle vertex is interior of valence 4.
    let g = Level::from_mesh(&grid(3, 1)).unwrap();
    assert_eq!((g.num_vertices, g.num_edges(), g.num_faces()), (9, 12, 4));
    for i in 0..3 {
        for j in 0..3 {
            let v = grid_id(3, i, j) as usize;
            let corner = (i == 0 || i == 2) && (j == 0 || j == 2);
            let middle = i == 1 && j == 1;
            assert_eq!(g.is_boundary_vertex(v), !middle, "grid vertex ({i}, {j})");
            let valence = if middle {
                4
            } else if corner {
                2
            } else {
                3
            };
            assert_eq!(g.valence(v), valence, "grid vertex ({i}, {j})");
        }
    }
    assert_eq!(
        (0..g.num_edges())
            .filter(|&e| g.is_boundary_edge(e))
            .count(),
        8
    );

    let cube = Level::from_mesh(&subdyn::examples::cube()).unwrap();
    assert_eq!(cube.num_edges(), 12);
    for v in 0..8 {
        assert!(!cube.is_boundary_vertex(v));
        assert_eq!(cube.valence(v), 3);
    }
    for e in 0..12 {
        assert!(!cube.is_boundary_edge(e));
        assert!(cube.edge_faces[e].iter().all(|&f| f != NONE));
    }

    let fan = Level::from_mesh(&reference_mesh("fan5_open")).unwrap();
    assert_eq!(fan.valence(0), 5);
    assert!(!fan.is_boundary_vertex(0));
    assert_eq!((1..11).filter(|&v| fan.is_boundary_vertex(v)).count(), 10);

    let mixed = Level::from_mesh(&mixed_mesh()).unwrap();
    let interior: Vec<usize> = (0..mixed.num_vertices)
        .filter(|&v| !mixed.is_boundary_vertex(v))
        .collect();
    assert_eq!(interior, vec![0, 1, 2, 3, 4]);
    assert_eq!(
        (0..5).map(|v| mixed.valence(v)).collect::<Vec<_>>(),
        vec![3, 4, 3, 3, 3]
    );
    // The tab's outer vertices have a single face.
    assert_eq!(mixed.vertex_faces(10).len(), 1);
    assert_eq!(mixed.valence(11), 2);
}

/// Checks the documented structure of `vertex_ring` at every vertex.
fn check_rings(l: &Level, name: &str) {
    for v in 0..l.num_vertices {
        let ring = l.vertex_ring(v);
        let nf = l.vertex_faces(v).len();
        assert_eq!(
            ring.faces.len(),
            nf,
            "{name}: vertex {v}: ring misses faces"
        );
        assert_eq!(
            ring.boundary,
            l.is_boundary_vertex(v),
            "{name}: vertex {v}: boundary flag"
        );
        let ne = if ring.boundary { nf + 1 } else { nf };
        assert_eq!(
            ring.edges.len(),
            ne,
            "{name}: vertex {v}: ring has {} edges",
            ring.edges.len()
        );
        let mut sorted_e = ring.edges.clone();
        sorted_e.sort_unstable();
        let mut all_e = l.vertex_edges(v).to_vec();
        all_e.sort_unstable();
        assert_eq!(
            sorted_e, all_e,
            "{name}: vertex {v}: ring edges are not the vertex's edges"
        );
        for (i, &f) in ring.faces.iter().enumerate() {
            let fe = l.face_edge_list(f as usize);
            let fv = l.face_vertices(f as usize);
            let c = fv.iter().position(|&x| x as usize == v).unwrap();
            // edges[i] leads out of v in faces[i]; edges[i + 1] comes into v.
            let lead = ring.edges[i];
            let trail = ring.edges[(i + 1) % ne];
            assert_eq!(
                fe[c], lead,
                "{name}: vertex {v}: edge {i} is not the leading edge of face {f}"
            );
            assert_eq!(
                fe[(c + fv.len() - 1) % fv.len()],
                trail,
                "{name}: vertex {v}: edge {} is not the trailing edge of face {f}",
                i + 1
            );
            // Consecutive faces are neighbours across the shared edge.
            if i + 1 < nf {
                let next = ring.faces[i + 1];
                let ef = l.edge_faces[trail as usize];
                assert!(
                    ef.contains(&f) && ef.contains(&next),
                    "{name}: vertex {v}: faces {f} and {next} do not share edge {trail}"
                );
            }
        }
        if ring.boundary {
            assert!(
                l.is_boundary_edge(ring.edges[0] as usize),
                "{name}: vertex {v}: ring starts inside"
            );
            assert!(
                l.is_boundary_edge(ring.edges[nf] as usize),
                "{name}: vertex {v}: ring ends inside"
            );
        } else if nf > 0 {
            let ef = l.edge_faces[ring.edges[0] as usize];
            assert!(
                ef.contains(&ring.faces[0]) && ef.contains(&ring.faces[nf - 1]),
                "{name}: vertex {v}: interior ring does not close"
            );
        }
    }
}

#[test]
fn vertex_rings_are_ordered_fans() {
    check_rings(
        &Level::from_mesh(&subdyn::examples::cube()).unwrap(),
        "cube",
    );
    check_rings(
        &Level::from_mesh(&reference_mesh("fan5_open")).unwrap(),
        "fan5_open",
    );
    check_rings(&Level::from_mesh(&grid(4, 2)).unwrap(), "grid");
    check_rings(&Level::from_mesh(&mixed_mesh()).unwrap(), "mixed mesh");
    check_rings(&Level::from_mesh(&pentagonal_pyramid()).unwrap(), "pyramid");
    // Refined levels too.
    let h = default_refiner(&mixed_mesh()).refine_uniform(2).unwrap();
    check_rings(h.level(2), "mixed mesh level 2");
    // The fan's centre: five faces in counter-clockwise order.
    let fan = Level::from_mesh(&reference_mesh("fan5_open")).unwrap();
    let ring = fan.vertex_ring(0);
    let start = ring.faces.iter().position(|&f| f == 0).unwrap();
    let rotated: Vec<u32> = (0..5).map(|i| ring.faces[(start + i) % 5]).collect();
    assert_eq!(
        rotated,
        vec![0, 1, 2, 3, 4],
        "fan centre ring is not counter-clockwise"
    );
}

#[test]
fn isolated_vertex_is_accepted_with_no_edges() {
    let mut mesh = mixed_mesh();
    mesh.positions.push(Point3::new(9.0, 9.0, 9.0));
    let l = Level::from_mesh(&mesh).unwrap();
    let v = mesh.num_vertices() - 1;
    assert_eq!(l.num_vertices, mesh.num_vertices());
    assert_eq!(l.valence(v), 0);
    assert!(!l.is_boundary_vertex(v));
    assert!(l.vertex_ring(v).faces.is_empty());
}

// ---------------------------------------------------------------------------
// Euler characteristic

fn euler(l: &Level) -> i64 {
    l.num_vertices as i64 - l.num_edges() as i64 + l.num_faces() as i64
}

#[test]
fn euler_characteristic_gives_genus() {
    let torus = subdyn::examples::torus(8, 6, 3.0, 1.0);
    let h = default_refiner(&torus).refine_uniform(2).unwrap();
    for k in 0..=2 {
        let l = h.level(k);
        assert_eq!(euler(l), 0, "torus level {k}: V − E + F");
        assert!((0..l.num_edges()).all(|e| !l.is_boundary_edge(e)));
    }
    let genus = (2 - euler(h.level(0))) / 2;
    assert_eq!(genus, 1);
    let reference = Level::from_mesh(&reference_mesh("torus_regular")).unwrap();
    assert_eq!(euler(&reference), 0, "torus_regular: V − E + F");

    for (name, mesh) in [
        ("cube", subdyn::examples::cube()),
        ("prism", triangular_prism()),
        ("pyramid", pentagonal_pyramid()),
    ] {
        let h = default_refiner(&mesh).refine_uniform(2).unwrap();
        for k in 0..=2 {
            assert_eq!(euler(h.level(k)), 2, "{name} level {k}: V − E + F");
        }
    }
    // A disk (one boundary loop): χ = 1.
    let h = default_refiner(&mixed_mesh()).refine_uniform(1).unwrap();
    assert_eq!(euler(h.level(0)), 1);
    assert_eq!(euler(h.level(1)), 1);
}

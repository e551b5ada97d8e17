//! Integration tests of `subdyn::io`: round trips for every format, the PLY
//! encodings and header shapes met in the wild, and one test per kind of bad
//! input, each checking the error variant and that the message names the problem.
//!
//! Fixtures: `tests/data/io/` (small hand-written files); binary PLY files are
//! built byte by byte below. The real scan `../shared/data/scans/bun045.ply`
//! and mesh `../shared/data/meshes/dragon_vrip_res4.ply.gz` are used when
//! present and skipped (with a note) otherwise.

use std::path::{Path, PathBuf};

use subdyn::Error;
use subdyn::io::*;
use subdyn::math::{Point3, Vector3};
use subdyn::mesh::{PointCloud, PolyMesh};
use subdyn::subdivision::{BoundaryRule, TriangleRule};
use subdyn::topology::CreaseMethod;

/// A fixture under `tests/data/io/`.
fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/io")
        .join(name)
}

/// A file under `../shared/data/` (its tests are ignored when that folder
/// is absent: `build.rs`).
fn shared(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data")
        .join(name)
}

/// Writes `bytes` to `dir/name` and returns the path.
fn file(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The line and message of a parse error; panics on any other result.
fn parse_error<T: std::fmt::Debug>(result: subdyn::Result<T>) -> (usize, String) {
    match result {
        Err(Error::Parse { line, message, .. }) => (line, message),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

/// A cube with quad faces, one face flipped into a pentagon by an extra vertex.
fn sample_mesh() -> PolyMesh {
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let positions = vec![
        p(0.1, 0.0, 0.0),
        p(1.0 / 3.0, 0.0, 0.0),
        p(1.0, 1.0, -0.0),
        p(0.0, 1.0, 0.0),
        p(0.0, 0.0, 1e-300),
        p(1.0, 0.0, 1.0),
        p(1.0, 1.0, 1.0),
        p(0.0, 1.0, 1.0),
        p(0.5, -0.25, 6.02e23),
    ];
    let faces = vec![
        vec![0, 3, 2, 1],
        vec![4, 5, 6, 7],
        vec![0, 1, 8, 5, 4],
        vec![1, 2, 6, 5],
        vec![2, 3, 7, 6],
        vec![3, 0, 4, 7],
    ];
    PolyMesh::from_faces(positions, &faces).unwrap()
}

/// One normal per vertex of [`sample_mesh`], with awkward decimals.
fn sample_normals(n: usize) -> Vec<Vector3> {
    (0..n)
        .map(|i| Vector3::new(0.1 * i as f64, -1.0 / 7.0, (i as f64).sqrt()))
        .collect()
}

// ---------------------------------------------------------------- round trips

#[test]
fn every_format_round_trips_a_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sample_mesh();
    for ext in ["obj", "ply", "off", "obj.gz", "ply.gz", "off.gz"] {
        let path = dir.path().join(format!("mesh.{ext}"));
        write_mesh(&path, &mesh, None).unwrap();
        assert_eq!(read_mesh(&path).unwrap(), mesh, "format {ext}");
    }
}

#[test]
fn xyz_keeps_the_points_of_a_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sample_mesh();
    let path = dir.path().join("mesh.xyz");
    write_mesh(&path, &mesh, None).unwrap();
    let back = read_mesh(&path).unwrap();
    assert_eq!(back.positions, mesh.positions);
    assert_eq!(back.num_faces(), 0);
}

#[test]
fn every_format_round_trips_normals() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sample_mesh();
    let normals = sample_normals(mesh.num_vertices());
    for ext in ["obj", "ply", "off", "xyz"] {
        let path = dir.path().join(format!("with_normals.{ext}"));
        write_mesh(&path, &mesh, Some(&normals)).unwrap();
        let cloud = read_points(&path).unwrap();
        assert_eq!(cloud.positions, mesh.positions, "format {ext}");
        assert_eq!(cloud.normals.as_ref(), Some(&normals), "format {ext}");
        if ext != "xyz" {
            assert_eq!(read_mesh(&path).unwrap(), mesh, "format {ext}");
        }
    }
    let obj = std::fs::read_to_string(dir.path().join("with_normals.obj")).unwrap();
    assert!(obj.contains("\nf 1//1 4//4 3//3 2//2\n"), "{obj}");
}

#[test]
fn every_format_round_trips_a_point_cloud() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sample_mesh();
    let with = PointCloud::new(
        mesh.positions.clone(),
        Some(sample_normals(mesh.num_vertices())),
    )
    .unwrap();
    let without = PointCloud::new(mesh.positions.clone(), None).unwrap();
    for ext in ["obj", "ply", "off", "xyz", "xyz.gz"] {
        for cloud in [&with, &without] {
            let path = dir.path().join(format!("cloud.{ext}"));
            write_points(&path, cloud).unwrap();
            assert_eq!(&read_points(&path).unwrap(), cloud, "format {ext}");
            assert_eq!(read_mesh(&path).unwrap().num_faces(), 0, "format {ext}");
        }
    }
    let header = std::fs::read(dir.path().join("cloud.ply")).unwrap();
    assert!(!String::from_utf8_lossy(&header[..200]).contains("element face"));
}

#[test]
fn binary_ply_is_exact_and_uses_uint_counts_only_for_big_faces() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sample_mesh();
    let path = dir.path().join("exact.ply");
    write_mesh(&path, &mesh, None).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.starts_with("ply\nformat binary_little_endian 1.0\n"));
    assert!(text.contains("property double x\n"));
    assert!(text.contains("property list uchar int vertex_indices\n"));
    let back = read_mesh(&path).unwrap();
    for (a, b) in back.positions.iter().zip(&mesh.positions) {
        for k in 0..3 {
            assert_eq!(a[k].to_bits(), b[k].to_bits());
        }
    }

    // A 300-gon needs a `uint` count.
    let n = 300;
    let ring: Vec<Point3> = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            Point3::new(t.cos(), t.sin(), 0.0)
        })
        .collect();
    let big = PolyMesh::from_faces(ring, &[(0..n as u32).collect()]).unwrap();
    let path = dir.path().join("big_face.ply");
    write_mesh(&path, &big, None).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert!(String::from_utf8_lossy(&bytes).contains("property list uint int vertex_indices\n"));
    assert_eq!(read_mesh(&path).unwrap(), big);
}

#[test]
fn writers_check_their_input() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sample_mesh();
    let path = dir.path().join("bad.obj");
    let short = sample_normals(3);
    assert!(
        matches!(write_mesh(&path, &mesh, Some(&short)), Err(Error::Input(m)) if m.contains("3 normals"))
    );
    let mut nan = sample_normals(mesh.num_vertices());
    nan[2].y = f64::NAN;
    assert!(
        matches!(write_mesh(&path, &mesh, Some(&nan)), Err(Error::Input(m)) if m.contains("normal 2"))
    );
    assert!(!path.exists());
    assert!(matches!(
        write_mesh(dir.path().join("mesh.stl"), &mesh, None),
        Err(Error::Input(_))
    ));
}

/// A caller can match on the kind of bad input, the message unchanged.
#[test]
fn input_errors_have_kinds() {
    use subdyn::InputKind;
    let dir = tempfile::tempdir().unwrap();
    let mesh = sample_mesh();
    let path = dir.path().join("bad.obj");
    let kind = |r: subdyn::Result<()>| r.unwrap_err().input_kind();
    let short = sample_normals(3);
    assert_eq!(
        kind(write_mesh(&path, &mesh, Some(&short))),
        Some(InputKind::SizeMismatch)
    );
    let mut nan = sample_normals(mesh.num_vertices());
    nan[2].y = f64::NAN;
    let e = write_mesh(&path, &mesh, Some(&nan)).unwrap_err();
    assert_eq!(e.input_kind(), Some(InputKind::NonFinite));
    assert_eq!(e.to_string(), "input: normal 2 is not finite");
    assert_eq!(
        kind(write_mesh(dir.path().join("mesh.stl"), &mesh, None)),
        Some(InputKind::Unsupported)
    );
    let refiner = subdyn::subdivision::Refiner::new(&mesh, &Default::default()).unwrap();
    let eval = subdyn::limit::LimitEvaluator::new(&refiner);
    let e = eval.stencil(mesh.num_faces(), 0.5, 0.5).unwrap_err();
    assert_eq!(e.input_kind(), Some(InputKind::OutOfRange), "{e}");
    assert!(
        read_mesh(dir.path().join("missing.obj"))
            .unwrap_err()
            .input_kind()
            .is_none()
    );
}

// ---------------------------------------------------------------------- OBJ

#[test]
fn obj_keeps_quads_and_pentagons_and_merges_groups() {
    let mesh = read_mesh(data("quads_pentagon.obj")).unwrap();
    assert_eq!(mesh.num_vertices(), 10);
    assert_eq!(mesh.num_faces(), 3);
    assert_eq!(mesh.face(0), &[0, 1, 2, 3]);
    assert_eq!(mesh.face(1), &[3, 2, 4]);
    assert_eq!(mesh.face(2), &[5, 9, 8, 7, 6]);
    assert_eq!(mesh.positions[4], Point3::new(0.5, 1.5, 0.0)); // `w` column ignored
    assert_eq!(mesh.positions[5], Point3::new(0.0, 0.0, -1.0)); // colour columns ignored
    // One `vn` for ten vertices: no normals.
    assert_eq!(
        read_points(data("quads_pentagon.obj")).unwrap().normals,
        None
    );
}

#[test]
fn obj_negative_indices_are_relative() {
    let mesh = read_mesh(data("negative_indices.obj")).unwrap();
    assert_eq!(mesh.face(0), &[0, 1, 2, 3]);
    assert_eq!(mesh.face(1), &[1, 4, 5, 2]);
}

#[test]
fn obj_from_bytes_reads_an_embedded_mesh_also_gzipped() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let mesh = read_obj_from_bytes(obj, Path::new("embedded.obj")).unwrap();
    assert_eq!(mesh.face(0), &[0, 1, 2]);

    use std::io::Write;
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(obj).unwrap();
    let gz = gz.finish().unwrap();
    let again = read_mesh_from_bytes(&gz, MeshFormat::Obj, Path::new("embedded.obj.gz")).unwrap();
    assert_eq!(again, mesh);
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data beside the clone")]
fn shared_obj_meshes_load() {
    for (name, vertices) in [
        ("meshes/spot.obj", 2930),
        ("meshes/fandisk.obj", 6475),
        ("meshes/rocker-arm.obj", 10044),
    ] {
        let path = shared(name);
        let mesh = read_mesh(&path).unwrap();
        assert_eq!(mesh.num_vertices(), vertices, "{name}");
        assert!(mesh.num_faces() > 0);
    }
}

// ---------------------------------------------------------------------- PLY

/// Builds a binary PLY body in either byte order.
struct Bin {
    big: bool,
    out: Vec<u8>,
}

impl Bin {
    fn new(big: bool, header: &str) -> Self {
        Bin {
            big,
            out: header.as_bytes().to_vec(),
        }
    }
    fn put<const N: usize>(&mut self, le: [u8; N], be: [u8; N]) -> &mut Self {
        self.out.extend_from_slice(if self.big { &be } else { &le });
        self
    }
    fn u8(&mut self, v: u8) -> &mut Self {
        self.out.push(v);
        self
    }
    fn i16(&mut self, v: i16) -> &mut Self {
        self.put(v.to_le_bytes(), v.to_be_bytes())
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.put(v.to_le_bytes(), v.to_be_bytes())
    }
    fn f32(&mut self, v: f32) -> &mut Self {
        self.put(v.to_le_bytes(), v.to_be_bytes())
    }
    fn f64(&mut self, v: f64) -> &mut Self {
        self.put(v.to_le_bytes(), v.to_be_bytes())
    }
}

const QUAD_POINTS: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.5, 0.5, 1.0],
];

/// A square pyramid (one quad, four triangles) in binary PLY, with a
/// `material` element before the vertices, an extra scalar and an extra
/// list property on each vertex, and an extra property on each face.
/// `uchar_counts` selects `list uchar int` (else `list int int`) face lists.
fn pyramid_ply(big: bool, uchar_counts: bool, vertex_count: usize) -> Vec<u8> {
    let format = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let count = if uchar_counts { "uchar" } else { "int" };
    let header = format!(
        "ply\nformat {format} 1.0\ncomment made by the test\n\
         element material 2\nproperty uchar red\nproperty double shine\n\
         element vertex {vertex_count}\nproperty float x\nproperty short quality\n\
         property float y\nproperty float z\nproperty list uchar float uv\n\
         element face 5\nproperty list {count} int vertex_indices\nproperty uchar flags\n\
         end_header\n"
    );
    let mut b = Bin::new(big, &header);
    b.u8(255).f64(0.5).u8(7).f64(1.5);
    for (i, p) in QUAD_POINTS.iter().enumerate() {
        b.f32(p[0]).i16(-(i as i16)).f32(p[1]).f32(p[2]);
        b.u8(2).f32(0.25).f32(0.75);
    }
    let faces: [&[i32]; 5] = [
        &[0, 3, 2, 1],
        &[0, 1, 4],
        &[1, 2, 4],
        &[2, 3, 4],
        &[3, 0, 4],
    ];
    for face in faces {
        if uchar_counts {
            b.u8(face.len() as u8);
        } else {
            b.i32(face.len() as i32);
        }
        for &v in face {
            b.i32(v);
        }
        b.u8(1);
    }
    b.out
}

fn check_pyramid(mesh: &PolyMesh) {
    assert_eq!(mesh.num_vertices(), 5);
    for (p, q) in mesh.positions.iter().zip(QUAD_POINTS) {
        assert_eq!(*p, Point3::new(q[0] as f64, q[1] as f64, q[2] as f64));
    }
    assert_eq!(mesh.num_faces(), 5);
    assert_eq!(mesh.face(0), &[0, 3, 2, 1]);
    assert_eq!(mesh.face(4), &[3, 0, 4]);
}

#[test]
fn binary_little_endian_ply_with_uchar_lists_and_extras() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(&dir, "pyramid_le.ply", &pyramid_ply(false, true, 5));
    check_pyramid(&read_mesh(&path).unwrap());
}

#[test]
fn binary_big_endian_ply_with_int_lists_and_extras() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(&dir, "pyramid_be.ply", &pyramid_ply(true, false, 5));
    check_pyramid(&read_mesh(&path).unwrap());
    let path = file(&dir, "pyramid_be_uchar.ply", &pyramid_ply(true, true, 5));
    check_pyramid(&read_mesh(&path).unwrap());
}

#[test]
fn binary_ply_with_double_normals_and_type_aliases() {
    let header = "ply\nformat binary_big_endian 1.0\nelement vertex 3\n\
                  property float64 x\nproperty float64 y\nproperty float64 z\n\
                  property float32 nx\nproperty float32 ny\nproperty float32 nz\nend_header\n";
    let mut b = Bin::new(true, header);
    for i in 0..3 {
        b.f64(i as f64 * 0.1).f64(1.0).f64(-2.0);
        b.f32(0.0).f32(0.0).f32(1.0);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = file(&dir, "normals.ply", &b.out);
    let cloud = read_points(&path).unwrap();
    assert_eq!(cloud.positions[2], Point3::new(0.2, 1.0, -2.0));
    assert_eq!(cloud.normals.unwrap()[1], Vector3::new(0.0, 0.0, 1.0));
    assert_eq!(read_mesh(&path).unwrap().num_faces(), 0);
}

#[test]
fn ascii_ply_with_obj_info_and_range_grid() {
    let cloud = read_points(data("scanner_header.ply")).unwrap();
    assert_eq!(cloud.len(), 4);
    // ASCII values keep their decimal value, whatever the declared type.
    assert_eq!(
        cloud.positions[3],
        Point3::new(-0.006, 0.0342903, 0.0711199)
    );
    assert_eq!(cloud.normals, None);
    assert_eq!(
        read_mesh(data("scanner_header.ply")).unwrap().num_faces(),
        0
    );
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data beside the clone")]
fn real_bunny_scan_loads_40097_points() {
    let path = shared("scans/bun045.ply");
    let cloud = read_points(&path).unwrap();
    assert_eq!(cloud.len(), 40_097);
    assert_eq!(
        cloud.positions[0],
        Point3::new(-0.0075, 0.0342091, 0.0703997)
    );
    assert_eq!(read_mesh(&path).unwrap().num_faces(), 0);
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data beside the clone")]
fn real_gzipped_dragon_loads() {
    let path = shared("meshes/dragon_vrip_res4.ply.gz");
    let mesh = read_mesh(&path).unwrap();
    assert_eq!(mesh.num_vertices(), 5205);
    assert_eq!(mesh.num_faces(), 11102);
    assert!(mesh.faces().all(|f| f.len() == 3));
}

// ---------------------------------------------------------------- OFF / XYZ

#[test]
fn off_variants_load() {
    let cube = read_mesh(data("cube.off")).unwrap();
    assert_eq!((cube.num_vertices(), cube.num_faces()), (8, 6));
    assert!(cube.faces().all(|f| f.len() == 4));
    assert_eq!(cube.face(5), &[3, 0, 4, 7]);

    let coloured = read_mesh(data("colored_triangle.off")).unwrap();
    assert_eq!(coloured.positions[1], Point3::new(1.0, 0.0, 0.0));
    assert_eq!(coloured.face(0), &[0, 1, 2]);

    let with_normals = read_points(data("normals_triangle.off")).unwrap();
    assert_eq!(
        with_normals.normals.unwrap()[2],
        Vector3::new(0.0, 0.0, 1.0)
    );
}

#[test]
fn xyz_variants_load() {
    let cloud = read_points(data("points.xyz")).unwrap();
    assert_eq!(cloud.len(), 3);
    assert_eq!(cloud.positions[0], Point3::new(1.5, 2.0, 3.0));
    assert_eq!(cloud.positions[2], Point3::new(-1e-3, 7.0, 8.0));
    assert_eq!(cloud.normals, None);

    let cloud = read_points(data("points_normals.xyz")).unwrap();
    assert_eq!(cloud.normals.unwrap()[2], Vector3::new(0.6, 0.0, 0.8));
}

// --------------------------------------------------------------- bad inputs

#[test]
fn truncated_ascii_ply_names_the_count_and_where_it_ends() {
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\nelement vertex 40097\nproperty float x\n\
                property float y\nproperty float z\nend_header\n"
        .to_string()
        + &"0 0 0\n".repeat(12);
    let path = file(&dir, "truncated.ply", text.as_bytes());
    let (line, message) = parse_error(read_points(&path));
    assert!(message.contains("expected 40097 vertices"), "{message}");
    assert!(message.contains("ends after 12"), "{message}");
    assert_eq!(line, 19);
}

#[test]
fn truncated_binary_ply_names_the_element_item() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = pyramid_ply(false, true, 5);
    bytes.truncate(bytes.len() - 20); // cut into the faces
    let path = file(&dir, "truncated.ply", &bytes);
    let (_, message) = parse_error(read_mesh(&path));
    assert!(
        message.contains("expected 5 faces, but the file ends after 3"),
        "{message}"
    );
}

#[test]
fn binary_ply_with_a_wrong_vertex_count_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    // Too many vertices declared: the faces' bytes are read as a vertex, and
    // the faces out of step.
    let path = file(&dir, "too_many.ply", &pyramid_ply(false, true, 6));
    let (_, message) = parse_error(read_mesh(&path));
    assert!(
        message.contains("an element count in the header is wrong"),
        "{message}"
    );
    // Too few: the faces are read from the last vertex's bytes, out of step.
    let path = file(&dir, "too_few.ply", &pyramid_ply(false, true, 4));
    let (_, message) = parse_error(read_mesh(&path));
    assert!(
        message.contains("an element count in the header is wrong"),
        "{message}"
    );
    // Extra bytes after the last element.
    let mut bytes = pyramid_ply(true, false, 5);
    bytes.extend_from_slice(&[0; 8]);
    let path = file(&dir, "trailing.ply", &bytes);
    let (_, message) = parse_error(read_mesh(&path));
    assert!(
        message.contains("8 bytes left after the last element"),
        "{message}"
    );
}

#[test]
fn bad_ply_headers_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "ply\nformat binary_middle_endian 1.0\nend_header\n",
            "unknown PLY format",
            2,
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\nend_header\n0 0\n",
            "no property `y`",
            3,
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
            "no `end_header`",
            4,
        ),
        (
            "plx\nformat ascii 1.0\nend_header\n",
            "first line must be `ply`",
            1,
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n",
            "unknown property type `quad`",
            4,
        ),
    ];
    for (text, expected, expected_line) in cases {
        let path = file(&dir, "header.ply", text.as_bytes());
        let (line, message) = parse_error(read_mesh(&path));
        assert!(message.contains(expected), "{message}");
        assert_eq!(line, expected_line, "{message}");
    }
}

#[test]
fn non_numeric_ascii_ply_token_names_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\ncomment c\nelement vertex 3\nproperty float x\n\
                property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n1 abc 0\n";
    let path = file(&dir, "token.ply", text.as_bytes());
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 11);
    assert!(
        message.contains("`abc`") && message.contains("property `y`"),
        "{message}"
    );
}

#[test]
fn ply_face_index_out_of_range_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
    let path = file(&dir, "range.ply", text.as_bytes());
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 13);
    assert!(
        message.contains("face 0 refers to vertex 3, but the file has 3 vertices"),
        "{message}"
    );
}

#[test]
fn obj_index_zero_is_rejected_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(&dir, "zero.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 0 1 2\n");
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 5);
    assert!(
        message.contains("index 0 is not valid (OBJ indices start at 1)"),
        "{message}"
    );
}

#[test]
fn obj_index_out_of_range_names_line_index_and_count() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(
        &dir,
        "range.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n",
    );
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 5);
    assert!(
        message.contains("vertex index 7") && message.contains("only 3 vertices"),
        "{message}"
    );

    let path = file(&dir, "relative.obj", b"v 0 0 0\nv 1 0 0\nf -1 -2 -3\n");
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 3);
    assert!(message.contains("relative index -3"), "{message}");
}

#[test]
fn obj_face_with_two_vertices_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(&dir, "two.obj", b"v 0 0 0\nv 1 0 0\nf 1 2\n");
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 3);
    assert!(message.contains("face 0 has 2 vertices"), "{message}");
}

#[test]
fn non_finite_coordinates_name_file_and_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[u8], usize); 4] = [
        ("nan.obj", b"# c\nv 0 0 0\nv 1 1 0\nv 1 nan 0\n", 4),
        ("inf.xyz", b"0 0 0\n1 2 3\n4 inf 6\n", 3),
        ("nan.off", b"OFF\n3 0 0\n0 0 0\n0 0 0\n0 0 NaN\n", 5),
        (
            "nan.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n0 0 0\nnan 0 0\n",
            10,
        ),
    ];
    for (name, bytes, expected_line) in cases {
        let path = file(&dir, name, bytes);
        let err = read_points(&path).unwrap_err();
        let shown = err.to_string();
        assert!(shown.contains(name), "{shown}");
        let (line, message) = parse_error::<()>(Err(err));
        assert_eq!(line, expected_line, "{name}: {message}");
        assert!(
            message.contains("vertex 2 has a non-finite coordinate"),
            "{message}"
        );
    }

    // Binary: the element index stands in for the line.
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n\
                  property double x\nproperty double y\nproperty double z\nend_header\n";
    let mut b = Bin::new(false, header);
    b.f64(0.0).f64(0.0).f64(0.0);
    b.f64(f64::INFINITY).f64(0.0).f64(0.0);
    b.f64(0.0).f64(0.0).f64(0.0);
    let path = file(&dir, "inf.ply", &b.out);
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 1);
    assert!(
        message.contains("vertex 1 has a non-finite coordinate (inf, 0, 0)"),
        "{message}"
    );
}

#[test]
fn empty_files_are_reported_as_empty() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["empty.obj", "empty.ply", "empty.off", "empty.xyz"] {
        let path = file(&dir, name, b"");
        let err = read_mesh(&path).unwrap_err();
        assert!(err.to_string().contains(name), "{err}");
        let (_, message) = parse_error::<()>(Err(err));
        assert!(message.contains("is empty"), "{message}");
    }
}

#[test]
fn files_without_vertices_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[u8]); 4] = [
        ("comments.obj", b"# nothing here\ng group\n"),
        ("comments.xyz", b"# only a comment\n\n"),
        ("zero.off", b"OFF\n0 0 0\n"),
        ("zero.ply", b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n"),
    ];
    for (name, bytes) in cases {
        let path = file(&dir, name, bytes);
        let (_, message) = parse_error(read_mesh(&path));
        assert!(message.contains("no vertices"), "{name}: {message}");
    }
}

#[test]
fn bad_off_and_xyz_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(&dir, "short.off", b"OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n");
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 5);
    assert!(
        message.contains("expected 4 vertices, but the file ends after 3"),
        "{message}"
    );

    let path = file(
        &dir,
        "index.off",
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n1 1 0\n3 0 1 3\n",
    );
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 6);
    assert!(message.contains("face 0 refers to vertex 3"), "{message}");

    let path = file(&dir, "columns.xyz", b"0 0 0\n1 1\n");
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 2);
    assert!(message.contains("expected 3 or 6 columns"), "{message}");

    let path = file(&dir, "mixed.xyz", b"0 0 0 0 0 1\n1 1 1\n");
    let (line, message) = parse_error(read_mesh(&path));
    assert_eq!(line, 2);
    assert!(message.contains("line 1 has 6"), "{message}");
}

#[test]
fn unknown_extensions_list_the_supported_ones() {
    for name in ["mesh.stl", "mesh", "archive.tar.gz"] {
        match MeshFormat::from_path(Path::new(name)) {
            Err(Error::Input(message)) => {
                assert!(message.contains(name), "{message}");
                assert!(message.contains(".obj, .ply, .off, .xyz"), "{message}");
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    assert!(matches!(
        read_mesh("does-not-matter.stl"),
        Err(Error::Input(_))
    ));
    assert!(matches!(
        read_mesh("missing-file.obj"),
        Err(Error::Io { .. })
    ));
}

#[test]
fn formats_follow_extensions_case_insensitively_through_gz() {
    let cases = [
        ("a.obj", MeshFormat::Obj),
        ("A.OBJ", MeshFormat::Obj),
        ("dir.v2/b.Ply", MeshFormat::Ply),
        ("c.ply.gz", MeshFormat::Ply),
        ("C.OBJ.GZ", MeshFormat::Obj),
        ("d.off", MeshFormat::Off),
        ("e.xyz.gz", MeshFormat::Xyz),
    ];
    for (name, format) in cases {
        assert_eq!(
            MeshFormat::from_path(Path::new(name)).unwrap(),
            format,
            "{name}"
        );
    }
}

// ------------------------------------------------------------------ creases

#[test]
fn creases_are_read_with_comments_and_infinite_sharpness() {
    let creases = read_tags(data("creases.txt")).unwrap().creases;
    assert_eq!(
        creases,
        vec![(0, 1, 2.5), (1, 2, f64::INFINITY), (3, 0, 0.0)]
    );
}

#[test]
fn tag_files_and_obj_tags_give_vertex_sharpness_and_holes() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(
        &dir,
        "t.creases",
        b"# edges, vertices, holes\n0 1 2\nv 3 1.5\nh 4\nv 2 inf\n",
    );
    let tags = read_tags(&path).unwrap();
    assert_eq!(tags.creases, vec![(0, 1, 2.0)]);
    assert_eq!(tags.corners, vec![(3, 1.5), (2, f64::INFINITY)]);
    assert_eq!(tags.holes, vec![4]);
    // OpenSubdiv's tag lines: a crease chain with one sharpness per edge,
    // corners with one sharpness for all, holes, the scheme options.
    let obj = file(
        &dir,
        "s.obj",
        b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n\
          t crease 3/2/0 0 1 2 1.5 3\nt corner 2/1/0 0 2 4.0\nt hole 1/0/0 0\n\
          t interpolateboundary 1/0/0 2\nt creasemethod 0/0/1 chaikin\n\
          t smoothtriangles 0/0/1 smooth\nt vertexedit 1/1/0 0 1.0\n",
    );
    let tags = read_obj_tags(&obj).unwrap();
    assert_eq!(tags.tags.creases, vec![(0, 1, 1.5), (1, 2, 3.0)]);
    assert_eq!(tags.tags.corners, vec![(0, 4.0), (2, 4.0)]);
    assert_eq!(tags.tags.holes, vec![0]);
    assert_eq!(tags.boundary, Some(BoundaryRule::EdgeOnly));
    assert_eq!(tags.crease_method, Some(CreaseMethod::Chaikin));
    assert_eq!(tags.triangles, Some(TriangleRule::Smooth));
    assert_eq!(tags.ignored, vec!["vertexedit".to_string()]);
    // The mesh itself reads as before.
    assert_eq!(read_mesh(&obj).unwrap().num_faces(), 1);
    for (text, expected) in [
        (&b"t crease 2/1/0 0 1\n"[..], "announces 2 ints, 1 floats"),
        (b"t crease 3/2/0 0 1 2 1 2 3\n", "announces"),
        (b"t crease 3/3/0 0 1 2 1 2 3\n", "expected 1 or 2"),
        (b"t interpolateboundary 1/0/0 7\n", "takes one of 0, 1, 2"),
        (b"t corner 1/1/0 0 -2\n", "sharpness must be"),
    ] {
        let bad = file(&dir, "bad.obj", text);
        let err = read_obj_tags(&bad).unwrap_err().to_string();
        assert!(
            err.contains("bad.obj:1:") && err.contains(expected),
            "{err}"
        );
    }
}

#[test]
fn bad_creases_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[u8], &str); 8] = [
        (b"0 1 1\n# c\n2 3 -1\n", "sharpness must be"),
        (b"0 1 1\n# c\nv 3 -1\n", "sharpness must be"),
        (b"0 1 1\n# c\nh x\n", "non-negative integer"),
        (b"0 1 1\n# c\n2 3 nan\n", "sharpness must be"),
        (b"0 1 1\n\n4 4 1\n", "two different vertices"),
        (b"0 1 1\n\n4 5\n", "found 2 columns"),
        (b"0 1 1\n\n4 5 1 2\n", "found 4 columns"),
        (b"0 1 1\n\n-4 5 1\n", "non-negative integer"),
    ];
    for (bytes, expected) in cases {
        let path = file(&dir, "bad.creases", bytes);
        let err = read_tags(&path).unwrap_err();
        assert!(err.to_string().contains("bad.creases:3:"), "{err}");
        let (line, message) = parse_error::<()>(Err(err));
        assert_eq!(line, 3);
        assert!(message.contains(expected), "{message}");
    }
}

// ------------------------------------------------------------- atomic_write

#[test]
fn atomic_write_leaves_nothing_when_the_writer_fails() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.txt");
    let result = atomic_write(&path, |w| {
        w.write_all(b"half of it")?;
        Err(std::io::Error::other("disk on fire"))
    });
    match result {
        Err(Error::Io { path: p, source }) => {
            assert_eq!(p, path);
            assert!(source.to_string().contains("disk on fire"));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "no file, no temp file"
    );
}

#[test]
fn atomic_write_replaces_a_file_whole_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(&dir, "out.txt", b"old contents, longer than the new ones\n");
    atomic_write(&path, |w| w.write_all(b"new\n")).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"new\n");

    let failed = atomic_write(&path, |w| {
        w.write_all(b"partial")?;
        Err(std::io::Error::other("stop"))
    });
    assert!(failed.is_err());
    assert_eq!(std::fs::read(&path).unwrap(), b"new\n");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn failed_mesh_write_keeps_the_previous_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = file(&dir, "keep.obj", b"v 0 0 0\n");
    let mesh = sample_mesh();
    let wrong = sample_normals(2);
    assert!(write_mesh(&path, &mesh, Some(&wrong)).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), b"v 0 0 0\n");
}

#[test]
fn cr_only_and_crlf_line_ends_are_lines() {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in [
        ("cr.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rv 1 1 0\rf 1 2 4 3\r"),
        (
            "crlf.obj",
            "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nv 1 1 0\r\nf 1 2 4 3\r\n",
        ),
        (
            "cr.off",
            "OFF\r4 1 0\r0 0 0\r1 0 0\r0 1 0\r1 1 0\r4 0 1 3 2\r",
        ),
    ] {
        let mesh = read_mesh(file(&dir, name, text.as_bytes())).unwrap();
        assert_eq!((mesh.num_vertices(), mesh.num_faces()), (4, 1), "{name}");
    }
    let cloud = read_points(file(&dir, "cr.xyz", b"0 0 0\r1 0 0\r0 1 0\r")).unwrap();
    assert_eq!(cloud.positions.len(), 3);
    // Line numbers count a CR-only line end once, a CRLF once.
    let (line, _) = parse_error(read_mesh(file(
        &dir,
        "bad.obj",
        b"v 0 0 0\r\nv 1 0\rf 1 2 3\r",
    )));
    assert_eq!(line, 2);
}

//! Invariants of the software rasteriser (`subdyn::render`) on tiny
//! hand-built scenes, and end-to-end runs of `subdyn render`.
//!
//! Every input is built by the test itself: a unit cube, jittered square
//! grids, a few points. CLI runs happen in a temporary directory and check
//! the PNG by decoding it with the `image` crate.

use std::path::Path;
use std::process::{Command, Output};

use subdyn::math::{Point3, Real};
use subdyn::mesh::{PointCloud, PolyMesh};
use subdyn::render::{
    Camera, CloudLayer, ColorMap, HLine, MeshLayer, Picture, PlotOptions, Projection,
    RenderOptions, Rgb, Scene, Series, distance_range, line_plot, log_tick_labels, log_ticks,
    nice_ticks, render, write_png,
};

const WHITE: Rgb = [255, 255, 255];

/// Options for a head-on orthographic view (azimuth 0, elevation 0) of a `w × h` picture.
fn head_on(w: u32, h: u32, margin: Real) -> RenderOptions {
    RenderOptions {
        width: w,
        height: h,
        azimuth: 0.0,
        elevation: 0.0,
        margin,
        ..RenderOptions::default()
    }
}

/// The unit cube `[0, 1]³`.
fn unit_cube() -> PolyMesh {
    subdyn::examples::cube()
}

/// A `n × n` grid of quads over `[0, 1]²` at height `z`, interior vertices
/// jittered within the plane by up to `jitter` of a cell, each quad split into two triangles along a
/// diagonal that alternates, so edges run in many directions.
fn jittered_plane(n: usize, jitter: Real, z: Real) -> PolyMesh {
    let mut positions = Vec::new();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as Real / (1u64 << 53) as Real - 0.5
    };
    for j in 0..=n {
        for i in 0..=n {
            let interior = i > 0 && i < n && j > 0 && j < n;
            let (dx, dy) = if interior {
                (random() * jitter, random() * jitter)
            } else {
                (0.0, 0.0)
            };
            let h = 1.0 / n as Real;
            positions.push(Point3::new((i as Real + dx) * h, (j as Real + dy) * h, z));
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                faces.push(vec![a, b, c]);
                faces.push(vec![a, c, d]);
            } else {
                faces.push(vec![a, b, d]);
                faces.push(vec![b, c, d]);
            }
        }
    }
    PolyMesh::from_faces(positions, &faces).unwrap()
}

/// Columns and rows `[x0, x1) × [y0, y1)` of the non-background pixels.
fn ink_box(p: &Picture) -> Option<(u32, u32, u32, u32)> {
    let mut b: Option<(u32, u32, u32, u32)> = None;
    for y in 0..p.height() {
        for x in 0..p.width() {
            if p.get(x, y) != Some(WHITE) {
                b = Some(match b {
                    None => (x, y, x + 1, y + 1),
                    Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1)),
                });
            }
        }
    }
    b
}

#[test]
fn a_unit_cube_seen_head_on_covers_exactly_the_fitted_square() {
    let cube = unit_cube();
    for (w, h) in [(200u32, 200u32), (300, 200), (200, 260)] {
        let scene = Scene {
            meshes: vec![MeshLayer::new(&cube)],
            ..Scene::default()
        };
        let picture = render(&scene, &head_on(w, h, 0.1)).unwrap();
        // Fitted side: the smaller side less 10 % of it on each end; centred.
        let side = w.min(h) * 8 / 10;
        let (x0, y0) = ((w - side) / 2, (h - side) / 2);
        for y in 0..h {
            for x in 0..w {
                let inside = (x0..x0 + side).contains(&x) && (y0..y0 + side).contains(&y);
                let drawn = picture.get(x, y) != Some(WHITE);
                assert_eq!(drawn, inside, "{w}×{h}: pixel ({x}, {y})");
            }
        }
    }
}

#[test]
fn the_near_triangle_hides_the_far_one_whatever_the_drawing_order() {
    let tri = |z: Real| {
        PolyMesh::from_faces(
            vec![
                Point3::new(0.0, 0.0, z),
                Point3::new(1.0, 0.0, z),
                Point3::new(0.3, 1.0, z),
            ],
            &[vec![0, 1, 2]],
        )
        .unwrap()
    };
    let (near, far) = (tri(1.0), tri(0.0));
    let mut near_layer = MeshLayer::new(&near);
    near_layer.color = [250, 0, 0];
    let mut far_layer = MeshLayer::new(&far);
    far_layer.color = [0, 0, 250];
    let options = head_on(120, 100, 0.05);
    let draw = |layers: Vec<MeshLayer>| {
        render(
            &Scene {
                meshes: layers,
                ..Scene::default()
            },
            &options,
        )
        .unwrap()
    };
    let a = draw(vec![near_layer.clone(), far_layer.clone()]);
    let b = draw(vec![far_layer, near_layer]);
    assert_eq!(a, b);
    let covered: Vec<Rgb> = a.pixels().iter().copied().filter(|&c| c != WHITE).collect();
    assert!(covered.len() > 2000);
    assert!(
        covered.iter().all(|c| c[0] > 150 && c[2] == 0),
        "a far (blue) pixel shows"
    );
}

#[test]
fn a_tessellated_square_seen_head_on_has_no_cracks() {
    // Unjittered grids put pixel centres exactly on the diagonals (the fill
    // rule decides them); jittered ones give edges in every direction.
    for (n, jitter, w, h) in [
        (18, 0.0, 200, 200),
        (10, 0.0, 120, 120),
        (17, 0.6, 97, 89),
        (40, 0.6, 200, 200),
        (64, 0.6, 331, 257),
    ] {
        let plane = jittered_plane(n, jitter, 0.0);
        let scene = Scene {
            meshes: vec![MeshLayer::new(&plane)],
            ..Scene::default()
        };
        let picture = render(&scene, &head_on(w, h, 0.05)).unwrap();
        let (x0, y0, x1, y1) = ink_box(&picture).expect("the plane is drawn");
        let mut holes = 0;
        for y in y0..y1 {
            for x in x0..x1 {
                holes += usize::from(picture.get(x, y) == Some(WHITE));
            }
        }
        assert_eq!(
            holes, 0,
            "{n}×{n} grid (jitter {jitter}) at {w}×{h}: background pixels inside the square"
        );
        // And the square is where the fit puts it.
        let side = w.min(h) - 2 * (w.min(h) as Real * 0.05).round() as u32;
        assert!((x1 - x0).abs_diff(side) <= 1 && (y1 - y0).abs_diff(side) <= 1);
    }
}

#[test]
fn point_splats_appear_at_their_projected_positions() {
    let points = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.2, 0.1),
        Point3::new(0.3, 1.0, -0.4),
        Point3::new(0.6, 0.5, 0.9),
    ];
    let cloud = PointCloud::new(points.clone(), None).unwrap();
    for (az, el, projection) in [
        (0.0, 0.0, Projection::Orthographic),
        (40.0, 25.0, Projection::Orthographic),
        (-70.0, 60.0, Projection::Perspective { fov_deg: 30.0 }),
    ] {
        let mut layer = CloudLayer::new(&cloud);
        layer.radius = 3.0;
        let scene = Scene {
            clouds: vec![layer],
            ..Scene::default()
        };
        let options = RenderOptions {
            width: 160,
            height: 120,
            azimuth: az,
            elevation: el,
            projection,
            margin: 0.1,
            ..RenderOptions::default()
        };
        let picture = render(&scene, &options).unwrap();
        let (lo, hi) = subdyn::math::bounding_box(&points).unwrap();
        let mut camera = Camera::orbit(lo, hi, az, el, projection).unwrap();
        camera.fit(&points, [0.0, 0.0, 160.0, 120.0], 0.1);
        for p in &points {
            let s = camera.project(p);
            let (x, y) = (s.x.floor() as u32, s.y.floor() as u32);
            assert_ne!(
                picture.get(x, y),
                Some(WHITE),
                "view {az},{el}: point {p:?} at ({x}, {y})"
            );
        }
        // Four disks of radius 3 (about 28 pixels each), nothing else.
        let drawn = picture.count(|c| c != WHITE);
        assert!(
            (4 * 20..=4 * 32).contains(&drawn),
            "view {az},{el}: {drawn} pixels drawn"
        );
    }
}

#[test]
fn the_colour_map_ends_are_viridis_ends() {
    assert_eq!(ColorMap::Viridis.color(0.0), [68, 1, 84]);
    assert_eq!(ColorMap::Viridis.color(1.0), [253, 231, 37]);
    assert_eq!(ColorMap::Viridis.color(-3.0), [68, 1, 84]);
    assert_eq!(ColorMap::Viridis.color(3.0), [253, 231, 37]);
    // Lightness rises monotonically (viridis is sequential).
    let luma = |c: Rgb| 0.2126 * c[0] as Real + 0.7152 * c[1] as Real + 0.0722 * c[2] as Real;
    let samples: Vec<Real> = (0..=50)
        .map(|i| luma(ColorMap::Viridis.color(i as Real / 50.0)))
        .collect();
    assert!(samples.windows(2).all(|w| w[1] > w[0]));
}

#[test]
fn a_legend_is_drawn_when_and_only_when_colouring() {
    let cube = unit_cube();
    let heights: Vec<Real> = cube.positions.iter().map(|p| p.y).collect();
    let options = RenderOptions {
        width: 480,
        height: 360,
        ..RenderOptions::default()
    };
    let strip = |p: &Picture| -> Vec<Rgb> {
        (0..p.height())
            .flat_map(|y| (p.width() * 85 / 100..p.width()).map(move |x| (x, y)))
            .filter_map(|(x, y)| p.get(x, y))
            .collect()
    };
    let plain = Scene {
        meshes: vec![MeshLayer::new(&cube)],
        ..Scene::default()
    };
    let picture = render(&plain, &options).unwrap();
    assert!(
        strip(&picture).iter().all(|&c| c == WHITE),
        "legend without scalars"
    );

    let coloured = Scene {
        meshes: vec![MeshLayer::new(&cube).with_scalars(&heights)],
        ..Scene::default()
    };
    let picture = render(&coloured, &options).unwrap();
    let legend = strip(&picture);
    for end in [0.0, 1.0] {
        let c = ColorMap::Viridis.color(end);
        assert!(legend.contains(&c), "legend bar lacks the colour of {end}");
    }
    // Tick labels: dark text ink.
    assert!(legend.iter().filter(|&&c| c == [30, 30, 30]).count() > 100);
    // The surface itself (left of the legend) uses the map: some pixels are purple, not grey.
    let purple = (0..picture.height())
        .flat_map(|y| (0..picture.width() * 3 / 4).map(move |x| (x, y)))
        .filter_map(|(x, y)| picture.get(x, y))
        .any(|c| c[2] > c[1] + 30 && c[0] > c[1] + 20);
    assert!(purple);
}

#[test]
fn geometry_is_never_clipped_in_any_view() {
    let cube = unit_cube();
    for projection in [
        Projection::Orthographic,
        Projection::Perspective { fov_deg: 30.0 },
    ] {
        for (az, el) in [
            (0.0, 0.0),
            (30.0, 20.0),
            (135.0, -45.0),
            (270.0, 90.0),
            (10.0, -90.0),
        ] {
            let scene = Scene {
                meshes: vec![MeshLayer::new(&cube)],
                ..Scene::default()
            };
            let options = RenderOptions {
                width: 100,
                height: 80,
                azimuth: az,
                elevation: el,
                projection,
                margin: 0.1,
                ..RenderOptions::default()
            };
            let picture = render(&scene, &options).unwrap();
            let (x0, y0, x1, y1) = ink_box(&picture).unwrap();
            assert!(
                x0 >= 7 && y0 >= 7 && x1 <= 93 && y1 <= 73,
                "{projection:?} {az},{el}: {x0},{y0}..{x1},{y1}"
            );
            // Fitted: touches the margin on at least one axis.
            assert!(
                x0 <= 9 || y0 <= 9,
                "{projection:?} {az},{el}: not fitted ({x0}, {y0})"
            );
        }
    }
}

#[test]
fn supersampling_keeps_the_size_and_softens_edges() {
    let cube = unit_cube();
    let scene = Scene {
        meshes: vec![MeshLayer::new(&cube)],
        ..Scene::default()
    };
    let hard = render(
        &scene,
        &RenderOptions {
            width: 120,
            height: 90,
            ..RenderOptions::default()
        },
    )
    .unwrap();
    let soft = render(
        &scene,
        &RenderOptions {
            width: 120,
            height: 90,
            supersample: 2,
            ..RenderOptions::default()
        },
    )
    .unwrap();
    assert_eq!((soft.width(), soft.height()), (120, 90));
    let distinct = |p: &Picture| {
        p.pixels()
            .iter()
            .collect::<std::collections::HashSet<_>>()
            .len()
    };
    assert!(distinct(&soft) > distinct(&hard));
}

#[test]
fn bad_options_are_errors_not_panics() {
    let cube = unit_cube();
    let scene = Scene {
        meshes: vec![MeshLayer::new(&cube)],
        ..Scene::default()
    };
    for options in [
        RenderOptions {
            width: 0,
            ..RenderOptions::default()
        },
        RenderOptions {
            height: 8193,
            ..RenderOptions::default()
        },
        RenderOptions {
            elevation: 91.0,
            ..RenderOptions::default()
        },
        RenderOptions {
            azimuth: Real::NAN,
            ..RenderOptions::default()
        },
        RenderOptions {
            supersample: 5,
            ..RenderOptions::default()
        },
        RenderOptions {
            projection: Projection::Perspective { fov_deg: 0.0 },
            ..RenderOptions::default()
        },
    ] {
        assert!(render(&scene, &options).is_err(), "{options:?}");
    }
    let heights = vec![0.0; 3];
    let wrong = Scene {
        meshes: vec![MeshLayer::new(&cube).with_scalars(&heights)],
        ..Scene::default()
    };
    assert!(render(&wrong, &RenderOptions::default()).is_err());
    assert!(render(&Scene::default(), &RenderOptions::default()).is_err());
}

#[test]
fn write_png_round_trips_and_leaves_nothing_on_failure() {
    let dir = tempfile::tempdir().unwrap();
    let mut picture = Picture::new(7, 5, [10, 20, 30]).unwrap();
    picture.set(6, 4, [200, 100, 0]);
    let path = dir.path().join("p.png");
    write_png(&path, &picture).unwrap();
    let back = image::open(&path).unwrap().to_rgb8();
    assert_eq!(back.dimensions(), (7, 5));
    assert_eq!(back.get_pixel(6, 4).0, [200, 100, 0]);
    assert_eq!(back.get_pixel(0, 0).0, [10, 20, 30]);
    assert!(write_png(&dir.path().join("missing/p.png"), &picture).is_err());
    assert!(write_png(&dir.path().join("p.jpg"), &picture).is_err());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

// ---------------------------------------------------------------------------
// Ticks, plots and the distance colour range

#[test]
fn log_ticks_follow_the_one_two_five_rule_with_at_least_three_labels() {
    assert_eq!(log_ticks((0.003, 2.0), 8), vec![0.01, 0.1, 1.0]);
    assert_eq!(log_ticks((0.03, 0.6), 8), vec![0.05, 0.1, 0.2, 0.5]);
    assert_eq!(
        log_ticks((0.06, 0.4), 8),
        vec![0.06, 0.07, 0.08, 0.09, 0.1, 0.2, 0.3, 0.4]
    );
    // Twelve decades, at most four labels: every fourth power of ten.
    assert_eq!(log_ticks((1e-6, 1e6), 4), vec![1e-4, 1.0, 1e4]);
    assert_eq!(
        log_tick_labels(&log_ticks((0.03, 0.6), 8)),
        vec!["0.05", "0.1", "0.2", "0.5"]
    );
    for range in [
        (0.011, 0.019),
        (1.1, 1.3),
        (0.2, 30.0),
        (2e-5, 3e-4),
        (7.0, 7.5),
    ] {
        let t = log_ticks(range, 8);
        assert!(t.len() >= 3, "{range:?}: {t:?}");
        assert!(t.windows(2).all(|w| w[0] < w[1]), "{range:?}: {t:?}");
        assert!(
            t.iter()
                .all(|&x| x >= range.0 * (1.0 - 1e-9) && x <= range.1 * (1.0 + 1e-9)),
            "{range:?}: {t:?}"
        );
        let labels = log_tick_labels(&t);
        let distinct: std::collections::HashSet<_> = labels.iter().collect();
        assert_eq!(distinct.len(), labels.len(), "{labels:?}");
    }
    // The time axis of a 3.4 s fit: four labelled ticks, not two.
    assert_eq!(nice_ticks((0.0, 3.4), 6), vec![0.0, 1.0, 2.0, 3.0]);
}

#[test]
fn a_plot_draws_its_tolerance_line_even_below_the_data_and_its_title() {
    let red = [200, 30, 30];
    let series = [Series {
        label: "p95".into(),
        points: vec![(0.0, 0.5), (1.0, 0.2), (2.0, 0.05)],
        color: [0, 0, 255],
    }];
    let plain = PlotOptions {
        log_y: true,
        ..PlotOptions::default()
    };
    let with_line = PlotOptions {
        title: Some("all points".into()),
        hlines: vec![HLine {
            y: 0.01,
            label: "tolerance".into(),
            color: red,
        }],
        ..plain.clone()
    };
    let a = line_plot(&series, &plain).unwrap();
    let b = line_plot(&series, &with_line).unwrap();
    assert_eq!(a.count(|c| c == red), 0);
    // Dashes across the plot (about half of ~580 pixels) and the label.
    assert!(b.count(|c| c == red) > 250, "{}", b.count(|c| c == red));
    // The title is ink in the top band, which is empty without it.
    let ink_on_top =
        |p: &Picture| (0..p.width()).any(|x| (2..14).any(|y| p.get(x, y) != Some(WHITE)));
    assert!(ink_on_top(&b) && !ink_on_top(&a));
    let bad = PlotOptions {
        hlines: vec![HLine {
            y: 0.0,
            label: "zero".into(),
            color: red,
        }],
        ..plain
    };
    assert!(line_plot(&series, &bad).is_err());
}

#[test]
fn the_distance_range_clips_one_hot_spot_at_the_99th_percentile() {
    let mut d: Vec<Real> = (0..999).map(|i| i as Real / 1000.0).collect();
    d.push(100.0);
    // Nearest rank 990 of 1,000: the 990th smallest value, 0.989.
    assert_eq!(distance_range(&d, 99.0), Some((0.0, 0.989)));
    assert_eq!(distance_range(&d, 100.0), Some((0.0, 100.0)));
    // Not-a-number values are left out; all zero but one: the top is the largest.
    let mut z = vec![0.0; 999];
    z.extend([3.0, Real::NAN]);
    assert_eq!(distance_range(&z, 99.0), Some((0.0, 3.0)));
    assert_eq!(distance_range(&[Real::NAN], 99.0), None);
    assert_eq!(distance_range(&[], 99.0), None);
}

// ---------------------------------------------------------------------------
// The command line

/// Runs `subdyn` with `args` in `dir`.
fn subdyn(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subdyn"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the subdyn binary runs")
}

/// [`subdyn`], asserting that it succeeded (the failure shows the
/// arguments and stderr).
fn succeeded(dir: &Path, args: &[&str]) -> Output {
    let out = subdyn(dir, args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A directory holding `cube.obj` (the unit cube as quads).
fn cube_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let cube = unit_cube();
    subdyn::io::write_mesh(dir.path().join("cube.obj"), &cube, None).unwrap();
    dir
}

/// Asserts a failed run: exit 1, one `subdyn: error: …` line mentioning
/// `needle`, and no file other than `cube.obj` left in `dir`.
fn assert_fails(dir: &Path, args: &[&str], needle: &str) {
    let out = subdyn(dir, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    assert!(stderr.starts_with("subdyn: error: "), "{args:?}: {stderr}");
    assert!(
        stderr.contains(needle),
        "{args:?}: {stderr:?} lacks {needle:?}"
    );
    let names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "cube.obj")
        .collect();
    assert!(names.is_empty(), "{args:?} left {names:?}");
}

#[test]
fn cli_writes_a_png_of_the_requested_size() {
    let dir = cube_dir();
    let out = succeeded(
        dir.path(),
        &[
            "render", "cube.obj", "-o", "cube.png", "--size", "160,120", "--view", "-30,25",
        ],
    );
    let png = image::open(dir.path().join("cube.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (160, 120));
    assert!(png.pixels().filter(|p| p.0 != WHITE).count() > 2000);
    assert!(String::from_utf8_lossy(&out.stdout).contains("160×120"));
}

#[test]
fn cli_draws_limit_surfaces_cages_points_and_distances() {
    let dir = cube_dir();
    let d = dir.path();
    std::fs::write(d.join("pts.xyz"), "0 0 0\n1 1 1\n0.5 0.5 1.2\n").unwrap();
    let runs: [&[&str]; 4] = [
        &[
            "render", "cube.obj", "-o", "a.png", "--limit", "4", "--cage", "--ssaa", "--title",
            "cube",
        ],
        &[
            "render",
            "pts.xyz",
            "-o",
            "b.png",
            "--point-size",
            "3",
            "--perspective",
        ],
        &[
            "render", "cube.obj", "-o", "c.png", "--points", "pts.xyz", "--cage",
        ],
        &[
            "render",
            "cube.obj",
            "-o",
            "d.png",
            "--limit",
            "3",
            "--color-by-distance-to",
            "cube.obj",
        ],
    ];
    for args in runs {
        succeeded(d, args);
        let png = image::open(d.join(args[3])).unwrap().to_rgb8();
        assert_eq!(png.dimensions(), (640, 480));
    }
    // Distances to the cage: the legend shows the colour map's ends.
    let png = image::open(d.join("d.png")).unwrap().to_rgb8();
    for end in [0.0, 1.0] {
        let c = ColorMap::Viridis.color(end);
        assert!(png.pixels().any(|p| p.0 == c), "no legend colour for {end}");
    }
}

#[test]
fn cli_clips_distance_colours_at_the_99th_percentile_unless_a_range_is_given() {
    let dir = cube_dir();
    let d = dir.path();
    // 300 points just above the cube's top face (0 to 0.3 % of its
    // diagonal away) and one hot spot 4 units above it.
    let mut xyz: String = (0..300)
        .map(|i| {
            let (x, y) = ((i % 20) as Real / 20.0, (i / 20) as Real / 15.0);
            format!("{x} {y} {}\n", 1.0 + 1e-5 * i as Real)
        })
        .collect();
    xyz.push_str("0.5 0.5 5\n");
    std::fs::write(d.join("pts.xyz"), xyz).unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "pts.xyz",
            "-o",
            "p.png",
            "--color-by-distance-to",
            "cube.obj",
        ];
        args.extend(extra);
        let out = succeeded(d, &args);
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let clipped = run(&[]);
    // The hot spot: 4 / √3 = 230.94 % of the diagonal.
    assert!(
        clipped.contains("the 99th percentile of the distances;")
            && clipped.contains("up to 230.94"),
        "{clipped}"
    );
    let full = run(&["--range", "0,250"]);
    assert!(!full.contains("99th percentile"), "{full}");
}

#[test]
fn cli_rejects_bad_sizes_views_and_outputs_with_one_line_and_no_file() {
    let dir = cube_dir();
    let d = dir.path();
    for (args, needle) in [
        (vec!["--size", "0,480"], "--size"),
        (vec!["--size", "9000,100"], "8192"),
        (vec!["--size", "640x480"], "W,H"),
        (vec!["--size", "-5,10"], "--size"),
        (vec!["--view", "30,95"], "elevation"),
        (vec!["--view", "abc"], "AZ,EL"),
        (vec!["--view", "1,2,3"], "AZ,EL"),
        (vec!["--view", "nan,0"], "azimuth"),
        (vec!["--range", "2,1"], "--range"),
        (vec!["--limit", "0"], "--limit"),
    ] {
        let mut all = vec!["render", "cube.obj", "-o", "out.png"];
        all.extend(args);
        assert_fails(d, &all, needle);
    }
    assert_fails(d, &["render", "cube.obj", "-o", "out.jpg"], ".png");
    assert_fails(
        d,
        &["render", "missing.obj", "-o", "out.png"],
        "missing.obj",
    );
    assert_fails(
        d,
        &[
            "render", "cube.obj", "-o", "out.png", "--points", "nope.xyz",
        ],
        "nope.xyz",
    );
    assert_fails(
        d,
        &[
            "render",
            "cube.obj",
            "-o",
            "out.png",
            "--color-by-distance-to",
            "nope.obj",
        ],
        "nope.obj",
    );
    assert_fails(
        d,
        &["render", "cube.obj", "-o", "no/such/dir/out.png"],
        "out.png",
    );
}

#[test]
fn pictures_side_by_side_keep_their_pixels_and_places() {
    let mut a = Picture::new(3, 2, [10, 10, 10]).unwrap();
    a.set(2, 1, [1, 2, 3]);
    let mut b = Picture::new(2, 4, [20, 20, 20]).unwrap();
    b.set(0, 3, [4, 5, 6]);
    let s = Picture::side_by_side(&[a, b]).unwrap();
    assert_eq!((s.width(), s.height()), (5, 4));
    assert_eq!(s.get(2, 1), Some([1, 2, 3]));
    assert_eq!(s.get(3, 3), Some([4, 5, 6]));
    assert_eq!(s.get(0, 0), Some([10, 10, 10]));
    assert_eq!(s.get(4, 0), Some([20, 20, 20]));
    // Below the shorter picture: the white background.
    assert_eq!(s.get(1, 3), Some([255, 255, 255]));
    assert!(Picture::side_by_side(&[]).is_err());
}

/// Pixels of exactly `color`.
fn count_color(png: &image::RgbImage, color: Rgb) -> usize {
    png.pixels().filter(|p| p.0 == color).count()
}

#[test]
fn labels_are_drawn_at_their_points() {
    let cube = unit_cube();
    let mut scene = Scene {
        meshes: vec![MeshLayer::wireframe(&cube, subdyn::render::EDGES)],
        ..Scene::default()
    };
    let options = RenderOptions {
        width: 200,
        height: 150,
        ..RenderOptions::default()
    };
    let plain = render(&scene, &options).unwrap();
    assert_eq!(plain.count(|c| c == subdyn::render::LABELS), 0);
    scene.labels = vec![subdyn::render::Label::new(cube.positions[0], "17")];
    let labelled = render(&scene, &options).unwrap();
    let ink = labelled.count(|c| c == subdyn::render::LABELS);
    assert!(ink > 10, "{ink} label pixels");
    // Near the projected point, not elsewhere: right of it and above.
    let (lo, hi) = subdyn::math::bounding_box(&cube.positions).unwrap();
    let mut camera = Camera::orbit(
        lo,
        hi,
        options.azimuth,
        options.elevation,
        options.projection,
    )
    .unwrap();
    camera.fit(&cube.positions, [0.0, 0.0, 200.0, 150.0], options.margin);
    let p = camera.project(&cube.positions[0]);
    for y in 0..150 {
        for x in 0..200 {
            if labelled.get(x, y) == Some(subdyn::render::LABELS) {
                let (dx, dy) = (f64::from(x) - p.x, f64::from(y) - p.y);
                assert!(
                    (0.0..=20.0).contains(&dx) && (-12.0..=2.0).contains(&dy),
                    "({x}, {y}) vs {p:?}"
                );
            }
        }
    }
}

#[test]
fn cli_draws_a_lattice_as_a_cage_with_numbered_control_points() {
    let dir = cube_dir();
    let d = dir.path();
    let lattice = subdyn(
        d,
        &[
            "lattice",
            "cube.obj",
            "--octree-levels",
            "1",
            "-o",
            "lat.json",
        ],
    );
    assert!(lattice.status.success());
    let mut inks = Vec::new();
    for (png, extra) in [
        ("plain.png", None),
        ("numbered.png", Some("--label-vertices")),
    ] {
        let mut args = vec!["render", "lat.json", "-o", png, "--size", "320,240"];
        args.extend(extra);
        let out = succeeded(d, &args);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("27 control points"), "{text}");
        assert!(
            text.contains(&format!("wrote {png} (picture, 320×240)")),
            "{text}"
        );
        let png = image::open(d.join(png)).unwrap().to_rgb8();
        assert!(count_color(&png, subdyn::render::EDGES) > 500, "cell edges");
        inks.push(count_color(&png, subdyn::render::LABELS));
    }
    assert_eq!(inks[0], 0);
    assert!(inks[1] > 27 * 10, "27 numbers: {} pixels", inks[1]);
    // Mesh-only options are refused with one line, and nothing is written.
    let out = subdyn(d, &["render", "lat.json", "-o", "x.png", "--limit", "2"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--limit is for meshes"), "{err}");
    assert!(!d.join("x.png").exists());
}

/// `--cage` draws a control mesh's sharp edges (its OBJ `t crease` tags, or
/// a `--creases` file) in red, over the limit surface or the mesh itself;
/// without tags there is no red.
#[test]
fn the_cage_shows_sharp_edges_in_red() {
    let dir = cube_dir();
    let cube = unit_cube();
    // The four edges round the face z = 1 (and through the file: the top
    // face's loop of vertices).
    let top: Vec<u32> = (0..cube.num_vertices() as u32)
        .filter(|&v| cube.positions[v as usize].z > 0.5)
        .collect();
    let face = cube
        .faces()
        .find(|f| f.iter().all(|v| top.contains(v)))
        .unwrap()
        .to_vec();
    let creases: Vec<(u32, u32, Real)> = (0..4)
        .map(|k| {
            (
                face[k].min(face[(k + 1) % 4]),
                face[k].max(face[(k + 1) % 4]),
                10.0,
            )
        })
        .collect();
    subdyn::io::write_mesh_with_creases(dir.path().join("tagged.obj"), &cube, None, &creases)
        .unwrap();
    let tags = subdyn::io::SubdivisionTags {
        creases,
        ..Default::default()
    };
    subdyn::io::write_tags(dir.path().join("top.creases"), &tags).unwrap();
    let red = |name: &str| -> usize {
        let picture = image::open(dir.path().join(name)).unwrap().to_rgb8();
        picture
            .pixels()
            .filter(|p| p.0 == subdyn::render::SHARP_EDGES)
            .count()
    };
    for (input, extra, out) in [
        ("tagged.obj", &[][..], "tagged.png"),
        ("tagged.obj", &["--limit", "4"][..], "tagged_limit.png"),
        ("cube.obj", &["--creases", "top.creases"][..], "file.png"),
        ("cube.obj", &[][..], "plain.png"),
    ] {
        let mut args = vec![
            "render", input, "--cage", "--view", "30,40", "-o", out, "--quiet",
        ];
        args.extend_from_slice(extra);
        succeeded(dir.path(), &args);
    }
    assert!(red("tagged.png") > 200, "{} red pixels", red("tagged.png"));
    assert!(red("tagged_limit.png") > 200);
    assert!(red("file.png") > 200);
    assert_eq!(red("plain.png"), 0);
}

//! Terrain in missions (issue 15): a GeoTIFF height map read with the
//! mission, the band above the ground in the θ-PSO cost (J3) and in
//! verification, and located errors for a missing or malformed file.

use nalgebra::Point3;
use skyform::mission;
use skyform::pipelines::theta_pso::{CostModel, flight, path::CentroidPath};

/// Writes a 101 × 21 float map (1 m pixels from (0, 0), rows northward):
/// flat at 0, or with a 20 m hill over x ∈ [40, 60].
fn write_map(path: &std::path::Path, hill: bool) {
    let (w, h) = (101u32, 21u32);
    let data: Vec<f32> = (0..w * h)
        .map(|i| {
            let x = (i % w) as f32;
            if hill && (40.0..=60.0).contains(&x) {
                20.0
            } else {
                0.0
            }
        })
        .collect();
    let file = std::fs::File::create(path).expect("create");
    let mut enc = tiff::encoder::TiffEncoder::new(file).expect("encoder");
    enc.write_image::<tiff::encoder::colortype::Gray32Float>(w, h, &data)
        .expect("write");
}

fn mission_text(file: &str) -> String {
    format!(
        r#"name = "terrain"
[bounds]
x = [0.0, 100.0]
y = [0.0, 20.0]
z = [5.0, 15.0]
[route]
start = [5.0, 10.0, 10.0]
goal = [95.0, 10.0, 10.0]
[terrain]
file = "{file}"
origin = [0.0, 0.0]
pixel_size = [1.0, 1.0]
lookup = "bilinear"
[formation]
uav_radius = 0.5
slots = [[0.0, 0.0, 0.0]]
[theta_pso]
waypoints = 2
"#
    )
}

/// J3 and the verification of the straight path start → goal, 10 m above
/// the ground at its ends.
fn judge(hill: bool) -> (f64, bool) {
    let dir = tempfile::tempdir().expect("tempdir");
    write_map(&dir.path().join("map.tif"), hill);
    let path = dir.path().join("m.toml");
    std::fs::write(&path, mission_text("map.tif")).expect("write");
    let m = mission::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    let points: Vec<Point3<f64>> = [m.route.start, m.route.goal]
        .iter()
        .map(|p| Point3::new(p.x, p.y, p.z + m.ground(p.x, p.y)))
        .collect();
    let path = CentroidPath::bare(points);
    let terms = CostModel::new(&m, &[]).terms(&path);
    let (_, v) = flight::fly(&m, &path, &[], &[]).unwrap_or_else(|e| panic!("{e}"));
    (terms.altitude, v.feasible)
}

#[test]
fn a_path_that_clears_the_band_over_flat_ground_does_not_over_a_hill() {
    let (j3_flat, ok_flat) = judge(false);
    assert_eq!(j3_flat, 0.0);
    assert!(ok_flat);
    let (j3_hill, ok_hill) = judge(true);
    assert!(j3_hill > 0.0, "J3 sees the hill");
    assert!(!ok_hill, "verification sees the hill");
}

#[test]
fn the_ground_is_read_with_the_missions_lookup() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_map(&dir.path().join("map.tif"), true);
    let path = dir.path().join("m.toml");
    std::fs::write(&path, mission_text("map.tif")).expect("write");
    let m = mission::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    assert_eq!(m.ground(50.0, 10.0), 20.0);
    assert_eq!(m.ground(39.5, 10.0), 10.0, "bilinear between 0 and 20");
    assert_eq!(m.ground(10.0, 10.0), 0.0);
}

#[test]
fn a_missing_or_malformed_terrain_file_is_a_located_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("m.toml");
    let text = mission_text("nowhere.tif");
    std::fs::write(&path, &text).expect("write");
    let checked = mission::check_str(&text, Some(&path.display().to_string()));
    let shown = checked.report.to_string();
    assert!(checked.report.has_errors());
    assert!(shown.contains("terrain.file"), "{shown}");
    assert!(shown.contains("cannot open"), "{shown}");
    assert!(shown.contains(":10:"), "located on its line: {shown}");

    std::fs::write(dir.path().join("bad.tif"), b"not a tiff at all").expect("write");
    let text = mission_text("bad.tif");
    let checked = mission::check_str(&text, Some(&path.display().to_string()));
    let shown = checked.report.to_string();
    assert!(
        shown.contains("terrain.file") && shown.contains("not a readable TIFF"),
        "{shown}"
    );
}

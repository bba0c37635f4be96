//! The mission as static data: bounds, obstacles, inspected surfaces, route,
//! terrain, IWPs and the mission file.

use rerun::RecordingStream;

use super::{f32x3, paths};
use crate::mission::{Mission, Obstacle, to_toml_string};
use crate::pipelines::Kind;

/// An obstacle's colour: inspected ones stand out.
fn obstacle_color(o: &Obstacle) -> rerun::Color {
    if o.inspect {
        rerun::Color::from_rgb(200, 90, 200)
    } else {
        rerun::Color::from_rgb(150, 150, 160)
    }
}

/// An obstacle's prism as a closed mesh from its base to its top: its
/// outline (a footprint's own vertices, a curve's ring at a centimetre)
/// triangulated (ear clipping, `geo`) for the caps, a quad per edge for the
/// sides. `None` for a disc, which Rerun draws as a cylinder.
fn footprint_mesh(o: &Obstacle) -> Option<rerun::Mesh3D> {
    use geo::TriangulateEarcut;
    let shape = o.outline();
    if shape.disc().is_some() {
        return None;
    }
    let ring: Vec<geo::Coord<f64>> = shape
        .ring(0.01)
        .iter()
        .map(|p| geo::coord! { x: p.x, y: p.y })
        .collect();
    let raw = geo::Polygon::new(geo::LineString::new(ring), Vec::new()).earcut_triangles_raw();
    let v = &raw.vertices;
    let n = v.len() as u32;
    let at = |p: &[f64; 2], z: f64| [p[0] as f32, p[1] as f32, z as f32];
    let vertices: Vec<[f32; 3]> = v
        .iter()
        .map(|p| at(p, o.base))
        .chain(v.iter().map(|p| at(p, o.height)))
        .collect();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for t in raw.triangle_indices.chunks_exact(3) {
        let [a, b, c] = [t[0] as u32, t[1] as u32, t[2] as u32];
        triangles.push([c, b, a]);
        triangles.push([a + n, b + n, c + n]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.push([i, j, j + n]);
        triangles.push([i, j + n, i + n]);
    }
    Some(rerun::Mesh3D::new(vertices).with_triangle_indices(triangles))
}

/// The mission as static data.
///
/// Long (~125 lines) because it logs the scene's layers one after another (band, footprints,
/// cylinders, inspected shells, route, terrain, IWPs, the mission file), each one static
/// Rerun archetype built in place.
pub fn log_scene(stream: &RecordingStream, m: &Mission) -> rerun::RecordingStreamResult<()> {
    stream.log_static(paths::WORLD, &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
    let b = &m.bounds;
    stream.log_static(
        paths::BOUNDS,
        &rerun::Boxes3D::from_mins_and_sizes(
            [[b.x[0] as f32, b.y[0] as f32, b.z[0] as f32]],
            [[
                (b.x[1] - b.x[0]) as f32,
                (b.y[1] - b.y[0]) as f32,
                (b.z[1] - b.z[0]) as f32,
            ]],
        )
        .with_labels(["altitude band"]),
    )?;
    for o in m.obstacles.iter().filter(|o| !o.is_wire()) {
        if let Some(mesh) = footprint_mesh(o) {
            stream.log_static(
                paths::footprint(&o.name),
                &mesh.with_albedo_factor(obstacle_color(o).0),
            )?;
        }
    }
    let wires: Vec<_> = m
        .obstacles
        .iter()
        .filter_map(|o| Some((o, o.wire.as_ref()?)))
        .collect();
    if !wires.is_empty() {
        stream.log_static(
            paths::WIRES,
            &rerun::LineStrips3D::new(wires.iter().map(|(_, w)| {
                [
                    [w.from.x as f32, w.from.y as f32, w.from.z as f32],
                    [w.to.x as f32, w.to.y as f32, w.to.z as f32],
                ]
            }))
            .with_radii(wires.iter().map(|(_, w)| w.radius as f32))
            .with_labels(wires.iter().map(|(o, _)| o.name.clone()))
            .with_colors(wires.iter().map(|_| rerun::Color::from_rgb(230, 160, 40))),
        )?;
    }
    let o: Vec<_> = m
        .obstacles
        .iter()
        .filter(|o| o.outline().disc().is_some())
        .collect();
    if !o.is_empty() {
        stream.log_static(
            paths::OBSTACLES,
            &rerun::Cylinders3D::from_lengths_and_radii(
                o.iter().map(|o| (o.height - o.base) as f32),
                o.iter().map(|o| o.radius as f32),
            )
            .with_centers(o.iter().map(|o| {
                [
                    o.center.x as f32,
                    o.center.y as f32,
                    ((o.base + o.height) / 2.0) as f32,
                ]
            }))
            .with_labels(o.iter().map(|o| o.name.clone()))
            .with_colors(o.iter().map(|o| obstacle_color(o))),
        )?;
        // Inspected surfaces (eq. 8): the stand-off band's outer shell,
        // translucent, over the altitude band.
        let inspected: Vec<_> = o.iter().filter(|o| o.inspect).collect();
        if !inspected.is_empty() {
            let band_height = (m.bounds.z[1] - m.bounds.z[0]) as f32;
            stream.log_static(
                paths::INSPECTION,
                &rerun::Cylinders3D::from_lengths_and_radii(
                    inspected.iter().map(|_| band_height),
                    inspected
                        .iter()
                        .map(|o| (o.radius + o.stand_off_band(&m.formation)[1]) as f32),
                )
                .with_centers(inspected.iter().map(|o| {
                    [
                        o.center.x as f32,
                        o.center.y as f32,
                        ((m.bounds.z[0] + m.bounds.z[1]) / 2.0) as f32,
                    ]
                }))
                .with_labels(inspected.iter().map(|o| {
                    let [lo, hi] = o.stand_off_band(&m.formation);
                    format!("inspect {}: {lo}-{hi} m", o.name)
                }))
                .with_colors(
                    inspected
                        .iter()
                        .map(|_| rerun::Color::from_unmultiplied_rgba(200, 90, 200, 40)),
                ),
            )?;
        }
    }
    stream.log_static(
        paths::ROUTE,
        &rerun::Points3D::new([f32x3(&m.route.start), f32x3(&m.route.goal)])
            .with_labels(["start", "goal"])
            .with_radii([0.6f32, 0.6])
            .with_colors([
                rerun::Color::from_rgb(60, 200, 60),
                rerun::Color::from_rgb(220, 60, 60),
            ]),
    )?;
    if let (Some(terrain), Some(map)) = (&m.terrain, m.height_map()) {
        log_terrain(stream, map, terrain.lookup)?;
    }
    // What each pipeline adds to the scene (θ-PSO: its IWPs).
    let mut sketch = super::sketch::RerunSketch::new(stream);
    for kind in Kind::ALL {
        kind.face().scene(m, &mut sketch);
    }
    sketch.result?;
    let toml = to_toml_string(m).unwrap_or_default();
    stream.log_static(
        paths::MISSION,
        &rerun::TextDocument::from_markdown(format!(
            "# {}\n\n{}\n\nskyform {}\n\n```toml\n{toml}\n```\n",
            m.name,
            m.description,
            env!("CARGO_PKG_VERSION")
        )),
    )?;
    Ok(())
}

/// The mission's height map as a mesh of at most 200 × 200 points, coloured
/// by height (`terrain::height_colour`: the hues of the designer's map, brighter).
fn log_terrain(
    stream: &RecordingStream,
    map: &crate::base::terrain::HeightMap,
    lookup: crate::base::terrain::Lookup,
) -> rerun::RecordingStreamResult<()> {
    let grid = crate::base::terrain::Grid::of(map, lookup, 200);
    let [low, high] = map.range;
    let span = f64::from(high - low).max(1e-9);
    stream.log_static(
        paths::TERRAIN,
        &rerun::Mesh3D::new(
            grid.points
                .iter()
                .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]),
        )
        .with_triangle_indices(grid.triangles())
        .with_vertex_colors(grid.points.iter().map(|p| {
            let [r, g, b] = crate::base::terrain::height_colour((p[2] - f64::from(low)) / span);
            rerun::Color::from_rgb(r, g, b)
        })),
    )
}

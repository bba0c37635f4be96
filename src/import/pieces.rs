//! One shape of a surveyed feature as the pieces it makes (posts, blocks,
//! decks, wires), read with its heights (`heights.rs`), and the geometry
//! that places them: clipping to the bounds, the wire's spans, a surface
//! rested on what stands under it. `obstacles.rs` names them.
//!
//! Long (~840 lines) because it is every reading of a shape's heights (a point, a wire, a
//! row, a polygon of six readings) with the geometry each needs (clipping, spans, the rest
//! pass), each a short function with the words the report gives.

use geo::{
    Area, BooleanOps, Coord, Intersects, LineString, MultiLineString, MultiPolygon, Polygon,
};
use nalgebra::{Point2, Point3};

use super::cover::{self, Disc};
use super::heights::{
    self, DEFAULT_DECK_THICKNESS, DEFAULT_WIRE_RADIUS, Props, WIRE_PIECE_RISE, metres, round_mm,
};
use super::obstacles::{DEFAULT_LINE_RADIUS, DEFAULT_POINT_RADIUS, Note, listing};
use super::{Drawn, Feature, Position, Shape};
use crate::mission::geodesy::Frame;
use crate::mission::{Bounds, Mission, Obstacle};

/// What one shape of a feature becomes, before it is named.
#[derive(Debug, Clone)]
pub(super) enum Piece {
    /// A cylinder standing from `base`; `top` `None`: no height known.
    Post {
        center: Point2<f64>,
        radius: f64,
        top: Option<f64>,
        base: f64,
    },
    /// A footprint from `base` to `top` (`None`: no height known).
    Block {
        footprint: Vec<Point2<f64>>,
        top: Option<f64>,
        base: f64,
    },
    /// A footprint whose top is known and whose underside is not yet:
    /// it rests on the survey's features under it (`rest_surfaces`), else
    /// stands on the ground (`on_ground`) or is a deck of the default depth.
    Surface {
        footprint: Vec<Point2<f64>>,
        top: f64,
        on_ground: bool,
    },
    Wire {
        from: Point3<f64>,
        to: Point3<f64>,
        radius: f64,
    },
}

/// A feature's pieces and what they carry over to its obstacles.
pub(super) struct Pending {
    pub(super) label: String,
    pub(super) name: String,
    pub(super) kind: Option<String>,
    pub(super) description: Option<String>,
    pub(super) overfly: Option<bool>,
    pub(super) pieces: Vec<Piece>,
    /// The reading of each shape, in words; a surface's is finished by the
    /// rest pass.
    pub(super) readings: Vec<String>,
    /// Its radius and height came from the survey (not a default): the
    /// merge keeps a known obstacle's own where they did not.
    pub(super) radius_known: bool,
    pub(super) height_known: bool,
}

/// What a shape's pieces are read against.
pub(super) struct Site<'a> {
    pub(super) mission: &'a Mission,
    pub(super) frame: &'a Frame,
    /// The origin's altitude, metres (absolute altitudes are less it).
    pub(super) origin: f64,
}

impl Site<'_> {
    fn enu(&self, p: &Position) -> Point2<f64> {
        self.frame.ground_to_enu(p.lat, p.lon)
    }

    /// The altitude of `p` above the ground under it, as `drawn` means it.
    fn above_ground(&self, p: &Position, drawn: &Drawn) -> Option<f64> {
        let q = self.enu(p);
        heights::above_ground(
            p.alt,
            drawn.vertical.mode,
            self.origin,
            self.mission.ground(q.x, q.y),
        )
    }
}

/// What one shape gave.
pub(super) enum Shaped {
    Pieces(Vec<Piece>, String),
    /// A point outside the bounds.
    Outside,
    /// A polygon of no area.
    NoArea,
    /// Nothing inside the bounds.
    Nothing,
}

/// What one shape's heights read as, before its kind is placed: the
/// drawing's altitudes above the ground, their extremes, and the words.
struct Drawing {
    /// How the drawing's altitudes are meant, in words (`relativeToGround,
    /// extruded`).
    how: String,
    /// Each position's altitude above the ground (empty: none drawn).
    alts: Vec<Option<f64>>,
    highest: f64,
    lowest: f64,
    /// Drawn above the ground (altitudes all on it are a shape on the ground).
    high: bool,
    /// The feature's `base`, else the ground.
    base: f64,
}

impl Drawing {
    /// "from the ground to 22 m", or "from 3 m to 22 m" above a base.
    fn standing_to(&self, top: f64) -> String {
        if self.base > 0.0 {
            format!("from {} to {}", metres(self.base), metres(top))
        } else {
            format!("from the ground to {}", metres(top))
        }
    }
}

/// The pieces of one shape of feature `f`, and the reading of its heights
/// in words; a problem when its heights cannot be read (a top below the
/// ground, a wire without a height). Properties first, then the drawing's
/// altitudes, then the defaults (`heights.rs` says why).
pub(super) fn shape_pieces(
    site: &Site<'_>,
    f: &Feature,
    drawn: &Drawn,
    props: &Props,
    marked_wire: bool,
    notes: &mut Vec<Note>,
) -> Result<Shaped, String> {
    let how = heights::how_drawn(drawn, site.origin);
    let alts: Vec<Option<f64>> = if drawn.has_altitudes() {
        drawn
            .shape
            .positions()
            .iter()
            .map(|p| site.above_ground(p, drawn))
            .collect()
    } else {
        Vec::new()
    };
    let highest = alts.iter().flatten().copied().fold(f64::NAN, f64::max);
    let lowest = alts.iter().flatten().copied().fold(f64::NAN, f64::min);
    // A top the drawing gives must stand above the ground.
    if highest.is_finite() && highest <= 0.0 && props.top.is_none() && !marked_wire {
        let drawn_on_ground = alts.iter().flatten().all(|a| a.abs() < 1e-6);
        if !drawn_on_ground {
            return Err(format!(
                "{}: its altitude is {} above the ground ({how}): at or below it; for an \
                 absolute altitude, `[origin] altitude` must be the ground's in the survey's \
                 datum (mean sea level for KML, the ellipsoid for GeoJSON)",
                f.label(),
                metres(highest)
            ));
        }
    }
    let d = Drawing {
        how,
        alts,
        highest,
        lowest,
        // Altitudes all on the ground are a shape drawn on the ground.
        high: highest.is_finite() && highest > 1e-6,
        base: props.base.unwrap_or(0.0),
    };
    match &drawn.shape {
        Shape::Point(p) => Ok(point(site, &d, p, props)),
        Shape::Line(points) => {
            let wire = marked_wire || (d.high && drawn.vertical.extrude != Some(true));
            if wire {
                wire_pieces(site, f, &d, points, props, marked_wire)
            } else {
                Ok(row(site, f, &d, points, props, notes))
            }
        }
        Shape::Polygon(rings) => Ok(polygon(site, f, &d, drawn, rings, props, notes)),
    }
}

/// A point: a post up to its `height`, else its altitude, else the default.
fn point(site: &Site<'_>, d: &Drawing, p: &Position, props: &Props) -> Shaped {
    let bounds = &site.mission.bounds;

    let center = site.enu(p);
    if !bounds.contains_xy(&center) {
        return Shaped::Outside;
    }
    let radius = props.radius.unwrap_or(DEFAULT_POINT_RADIUS);
    let (top, why) = match (props.top, d.high) {
        (Some(t), true) => (
            Some(t),
            format!("its `height`, not its drawn altitude {}", metres(d.highest)),
        ),
        (Some(t), false) => (Some(t), "its `height`".to_owned()),
        (None, true) => (Some(d.highest), format!("its altitude, {}", d.how)),
        (None, false) => (None, "no height: the default".to_owned()),
    };
    let shown = top.map_or_else(|| "the default height".into(), |t| d.standing_to(t));
    let piece = post_in_bounds(center, radius, top, d.base, bounds);
    let clipped = if matches!(piece, Piece::Block { .. }) {
        ", clipped to the bounds"
    } else {
        ""
    };
    Shaped::Pieces(
        vec![piece],
        format!(
            "a post of radius {} {shown} ({why}){clipped}",
            metres(radius)
        ),
    )
}

/// A line that is a wire: spans at its altitudes (or its `height`),
/// clipped to the bounds, sloped ones cut so each piece's box hugs it.
fn wire_pieces(
    site: &Site<'_>,
    f: &Feature,
    d: &Drawing,
    points: &[Position],
    props: &Props,
    marked_wire: bool,
) -> Result<Shaped, String> {
    let bounds = &site.mission.bounds;

    let radius = props.radius.unwrap_or(DEFAULT_WIRE_RADIUS);
    let zs: Vec<f64> = if d.high && props.top.is_none() {
        d.alts.iter().map(|a| a.unwrap_or(0.0)).collect()
    } else if let Some(t) = props.top {
        vec![t; points.len()]
    } else {
        return Err(format!(
            "{}: a wire needs its height: draw it with altitudes (relativeToGround) \
             or give it a `height` property, metres above the ground",
            f.label()
        ));
    };
    let line: Vec<Point3<f64>> = points
        .iter()
        .zip(&zs)
        .map(|(p, z)| {
            let q = site.enu(p);
            Point3::new(q.x, q.y, *z)
        })
        .collect();
    let spans = wire_spans(&line, bounds);
    if spans.is_empty() {
        return Ok(Shaped::Nothing);
    }
    let length: f64 = spans.iter().map(|(a, b)| (b.xy() - a.xy()).norm()).sum();
    let (lo, hi) = spans
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |acc, (a, b)| {
            (acc.0.min(a.z).min(b.z), acc.1.max(a.z).max(b.z))
        });
    let at = if hi - lo < 1e-3 {
        format!("at {}", metres(hi))
    } else {
        format!("from {} to {}", metres(lo), metres(hi))
    };
    let why = match (props.top, d.high) {
        (Some(_), _) => "its `height`".to_owned(),
        _ => format!("its altitudes, {}", d.how),
    };
    let marked = if marked_wire && !d.high {
        ", marked as a power line or cable"
    } else {
        ""
    };
    let pieces: Vec<Piece> = spans
        .into_iter()
        .map(|(from, to)| Piece::Wire {
            from: round3(from),
            to: round3(to),
            radius,
        })
        .collect();
    let count = pieces.len();
    Ok(Shaped::Pieces(
        pieces,
        format!(
            "a wire {at} ({why}{marked}), {length:.1} m in {count} span(s), kept {} \
             round its conductor beyond r_Q and the margins",
            metres(radius)
        ),
    ))
}

/// Another line: a row of posts up to its `height`, else its altitude
/// (extruded), else the default; clipped so no post reaches out of the
/// bounds.
fn row(
    site: &Site<'_>,
    f: &Feature,
    d: &Drawing,
    points: &[Position],
    props: &Props,
    notes: &mut Vec<Note>,
) -> Shaped {
    let bounds = &site.mission.bounds;
    let radius = props.radius.unwrap_or(DEFAULT_LINE_RADIUS);
    let (top, why) = match (props.top, d.high) {
        (Some(t), _) => (Some(t), "its `height`".to_owned()),
        (None, true) => (Some(d.highest), format!("its altitude, {}", d.how)),
        (None, false) => (None, "no height: the default".to_owned()),
    };
    let line: Vec<Point2<f64>> = points.iter().map(|p| site.enu(p)).collect();
    // Clipped so that no post of the row reaches out of the bounds.
    let (pieces, length, outside) = clip_line(&line, &rectangle_within(bounds, radius));
    let discs: Vec<Disc> = pieces
        .iter()
        .flat_map(|piece| cover::cover_line(piece, radius))
        .collect();
    if discs.is_empty() {
        return Shaped::Nothing;
    }
    notes.push(Note::Line {
        label: f.label(),
        cylinders: discs.len(),
        radius,
        length,
        outside,
    });
    let shown = top.map_or_else(|| "the default height".into(), |t| d.standing_to(t));
    Shaped::Pieces(
        discs
            .into_iter()
            .map(|disc| Piece::Post {
                center: round2(disc.center),
                radius: disc.radius,
                top,
                base: d.base,
            })
            .collect(),
        format!("a row of posts {shown} ({why})"),
    )
}

/// What makes a polygon's piece of each of its footprints.
type MakePiece = Box<dyn Fn(Vec<Point2<f64>>) -> Piece>;

/// A polygon: its footprints (clipped to the bounds), a block up to its
/// `height` or its altitude (extruded), a slab between its altitudes or
/// its `base`, a deck of its `thickness`, or a surface that rests on what
/// stands under it (`rest_surfaces`).
///
/// Long (~120 lines) because it is one choice among the readings of a polygon's heights (a
/// match of six arms, each the piece it makes and the words the report gives).
#[allow(clippy::too_many_arguments)]
fn polygon(
    site: &Site<'_>,
    f: &Feature,
    d: &Drawing,
    drawn: &Drawn,
    rings: &[Vec<Position>],
    props: &Props,
    notes: &mut Vec<Note>,
) -> Shaped {
    let bounds = &site.mission.bounds;
    let (highest, lowest, base) = (d.highest, d.lowest, d.base);

    let enu = |p: &Position| site.enu(p);
    let Some(polygon) = enu_polygon(rings, &enu) else {
        return Shaped::Nothing;
    };
    let whole = polygon.unsigned_area();
    if whole <= 1e-6 {
        return Shaped::NoArea;
    }
    let inside = rectangle(bounds).intersection(&polygon);
    let area = inside.unsigned_area();
    if area <= 1e-6 {
        return Shaped::Nothing;
    }
    let mut footprints = Vec::new();
    let mut holes = 0;
    for part in &inside {
        holes += part.interiors().len();
        if let Some(outline) = footprint_of(part.exterior()) {
            footprints.push(outline);
        }
    }
    notes.push(Note::Polygon {
        label: f.label(),
        footprints: footprints.len(),
        vertices: footprints.iter().map(Vec::len).sum(),
        area,
        holes,
        outside: (whole - area).max(0.0),
    });
    let sloped = d.high && highest - lowest > 1e-3;
    let (make, words): (MakePiece, String) = match (props.top, d.high, drawn.vertical.extrude) {
        (Some(t), _, _) => (
            Box::new(move |v| Piece::Block {
                footprint: v,
                top: Some(t),
                base,
            }),
            format!("a block {} (its `height`)", d.standing_to(t)),
        ),
        (None, true, Some(true)) => (
            Box::new(move |v| Piece::Block {
                footprint: v,
                top: Some(highest),
                base,
            }),
            format!(
                "a block {} (its altitude, {})",
                d.standing_to(highest),
                d.how
            ),
        ),
        (None, true, _) if sloped || props.base.is_some() => {
            let under = props.base.unwrap_or(lowest).min(highest);
            (
                Box::new(move |v| Piece::Block {
                    footprint: v,
                    top: Some(highest),
                    base: under,
                }),
                format!(
                    "a slab from {} to {} (its {}, {})",
                    metres(under),
                    metres(highest),
                    if props.base.is_some() {
                        "`base` and its altitude"
                    } else {
                        "lowest and highest altitudes"
                    },
                    d.how
                ),
            )
        }
        (None, true, extrude) => match props.thickness {
            Some(t) => (
                Box::new(move |v| Piece::Block {
                    footprint: v,
                    top: Some(highest),
                    base: (highest - t).max(0.0),
                }),
                format!(
                    "a deck from {} to {} (its altitude, {}, and its `thickness`)",
                    metres((highest - t).max(0.0)),
                    metres(highest),
                    d.how
                ),
            ),
            None => (
                Box::new(move |v| Piece::Surface {
                    footprint: v,
                    top: highest,
                    on_ground: extrude.is_none(),
                }),
                format!("{} (its altitude, {})", metres(highest), d.how),
            ),
        },
        (None, false, _) => (
            Box::new(move |v| Piece::Block {
                footprint: v,
                top: None,
                base,
            }),
            "a block of the default height (no height)".to_owned(),
        ),
    };
    let pieces: Vec<Piece> = footprints.into_iter().map(make).collect();
    if pieces.is_empty() {
        return Shaped::Nothing;
    }
    Shaped::Pieces(pieces, words)
}

/// Gives every surface its underside: the highest top of what the same
/// survey stands under it (a deck on its piers), else the ground (a
/// GeoJSON polygon with a height: a building), else `DEFAULT_DECK_THICKNESS`
/// below its top, with a warning. Finishes their readings.
pub(super) fn rest_surfaces(pending: &mut [Pending]) -> Vec<String> {
    // What stands: every post and block with a known top; the surfaces
    // join it as they are rested, lowest first (a GeoJSON survey's piers
    // are surfaces too, resolved onto the ground before the deck on them).
    let mut standing: Vec<(Vec<Point2<f64>>, f64)> = pending
        .iter()
        .flat_map(|p| &p.pieces)
        .filter_map(|piece| match piece {
            Piece::Post {
                center,
                radius,
                top: Some(t),
                ..
            } => Some((circle(*center, *radius), *t)),
            Piece::Block {
                footprint,
                top: Some(t),
                ..
            } => Some((footprint.clone(), *t)),
            _ => None,
        })
        .collect();
    let mut surfaces: Vec<(usize, usize, f64)> = Vec::new();
    for (i, p) in pending.iter().enumerate() {
        for (k, piece) in p.pieces.iter().enumerate() {
            if let Piece::Surface { top, .. } = piece {
                surfaces.push((i, k, *top));
            }
        }
    }
    surfaces.sort_by(|a, b| a.2.total_cmp(&b.2));
    let mut thin = Vec::new();
    let mut rests: Vec<Vec<String>> = vec![Vec::new(); pending.len()];
    for (i, k, top) in surfaces {
        let p = &mut pending[i];
        let Piece::Surface {
            footprint,
            on_ground,
            ..
        } = &mut p.pieces[k]
        else {
            continue;
        };
        let area = as_polygon(footprint);
        let under = standing
            .iter()
            .filter(|(v, t)| *t < top - 1e-6 && as_polygon(v).intersects(&area))
            .map(|(_, t)| *t)
            .fold(f64::NEG_INFINITY, f64::max);
        let (base, words) = if under.is_finite() {
            (
                under,
                format!(
                    "a deck from {} to {}, resting on what stands under it",
                    metres(under),
                    metres(top)
                ),
            )
        } else if *on_ground {
            (
                0.0,
                format!(
                    "a block from the ground to {} (a polygon with a height and nothing \
                     under it: a building)",
                    metres(top)
                ),
            )
        } else {
            let base = (top - DEFAULT_DECK_THICKNESS).max(0.0);
            thin.push(p.label.clone());
            (
                base,
                format!(
                    "a deck from {} to {}, {} deep assumed",
                    metres(base),
                    metres(top),
                    metres(DEFAULT_DECK_THICKNESS)
                ),
            )
        };
        let footprint = std::mem::take(footprint);
        standing.push((footprint.clone(), top));
        p.pieces[k] = Piece::Block {
            footprint,
            top: Some(top),
            base,
        };
        rests[i].push(words);
    }
    for (p, rests) in pending.iter_mut().zip(rests) {
        // The surface's reading is its top's words; what it rests on comes first.
        for (reading, rest) in p
            .readings
            .iter_mut()
            .filter(|r| !r.starts_with("a "))
            .zip(rests)
        {
            *reading = format!("{rest} (its top: {reading})");
        }
    }
    if thin.is_empty() {
        Vec::new()
    } else {
        vec![format!(
            "{}: a surface not extruded with nothing of the survey under it: {} deep assumed \
             below its altitude (give it a `thickness` or a `base` property, metres)",
            listing(&thin),
            metres(DEFAULT_DECK_THICKNESS)
        )]
    }
}

/// The obstacle a piece makes, named `name`, its other fields at their
/// defaults (the caller sets kind, description, overfly).
pub(super) fn obstacle(name: String, piece: &Piece, default_height: f64) -> Obstacle {
    match piece {
        Piece::Post {
            center,
            radius,
            top,
            base,
        } => {
            let mut o = Obstacle::standing(
                name,
                *center,
                *radius,
                round_mm(top.unwrap_or(default_height)),
            );
            o.base = round_mm(*base);
            o
        }
        Piece::Block {
            footprint,
            top,
            base,
        } => {
            let mut o = Obstacle::standing(
                name,
                Point2::origin(),
                0.0,
                round_mm(top.unwrap_or(default_height)),
            );
            o.footprint = footprint.clone();
            o.base = round_mm(*base);
            o.settle();
            o
        }
        Piece::Surface { footprint, top, .. } => {
            // Not reached: `rest_surfaces` turns every surface into a block.
            let mut o = Obstacle::standing(name, Point2::origin(), 0.0, round_mm(*top));
            o.footprint = footprint.clone();
            o.base = round_mm((*top - DEFAULT_DECK_THICKNESS).max(0.0));
            o.settle();
            o
        }
        Piece::Wire { from, to, radius } => Obstacle::wire(name, *from, *to, *radius),
    }
}

/// A post at `center`: a cylinder when it stays inside the bounds, else
/// its footprint (a 24-gon about the circle) clipped to them, so nothing
/// reaches out.
fn post_in_bounds(
    center: Point2<f64>,
    radius: f64,
    top: Option<f64>,
    base: f64,
    bounds: &Bounds,
) -> Piece {
    let inside = center.x - radius >= bounds.x[0]
        && center.x + radius <= bounds.x[1]
        && center.y - radius >= bounds.y[0]
        && center.y + radius <= bounds.y[1];
    if inside {
        return Piece::Post {
            center: round2(center),
            radius,
            top,
            base,
        };
    }
    let disc = MultiPolygon::new(vec![as_polygon(&circle(center, radius))]);
    let clipped = rectangle(bounds).intersection(&disc);
    match clipped
        .iter()
        .next()
        .and_then(|p| footprint_of(p.exterior()))
    {
        Some(footprint) => Piece::Block {
            footprint,
            top,
            base,
        },
        None => Piece::Post {
            center: round2(center),
            radius,
            top,
            base,
        },
    }
}

/// A polygon of 24 vertices round the circle (its sides touch it, so the
/// circle is inside).
fn circle(center: Point2<f64>, radius: f64) -> Vec<Point2<f64>> {
    let n = 24;
    let out = radius / (std::f64::consts::PI / n as f64).cos();
    (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            center + nalgebra::Vector2::new(a.cos(), a.sin()) * out
        })
        .collect()
}

fn as_polygon(v: &[Point2<f64>]) -> Polygon<f64> {
    let mut ring: Vec<Coord<f64>> = v.iter().map(|p| Coord { x: p.x, y: p.y }).collect();
    if let Some(first) = ring.first().copied() {
        ring.push(first);
    }
    Polygon::new(LineString::new(ring), Vec::new())
}

/// The parts of each segment of a wire's `line` over the bounds (its
/// heights interpolated where a side cuts it), each cut into spans that
/// rise at most `WIRE_PIECE_RISE`.
fn wire_spans(line: &[Point3<f64>], bounds: &Bounds) -> Vec<(Point3<f64>, Point3<f64>)> {
    let mut out = Vec::new();
    for pair in line.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let Some((t0, t1)) = clip_segment(a.xy(), b.xy(), bounds) else {
            continue;
        };
        let (p, q) = (a + (b - a) * t0, a + (b - a) * t1);
        if (q.xy() - p.xy()).norm() < 1e-3 && (q.z - p.z).abs() < 1e-3 {
            continue;
        }
        let pieces = ((q.z - p.z).abs() / WIRE_PIECE_RISE).ceil().max(1.0) as usize;
        for k in 0..pieces {
            let (s, e) = (k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64);
            out.push((p + (q - p) * s, p + (q - p) * e));
        }
    }
    out
}

/// The parameter range [t0, t1] of segment a → b inside the x-y bounds
/// (Liang-Barsky), or `None` when it misses them.
fn clip_segment(a: Point2<f64>, b: Point2<f64>, bounds: &Bounds) -> Option<(f64, f64)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, q) in [
        (-d.x, a.x - bounds.x[0]),
        (d.x, bounds.x[1] - a.x),
        (-d.y, a.y - bounds.y[0]),
        (d.y, bounds.y[1] - a.y),
    ] {
        if p.abs() < 1e-15 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

fn round2(p: Point2<f64>) -> Point2<f64> {
    Point2::new(round_mm(p.x), round_mm(p.y))
}

fn round3(p: Point3<f64>) -> Point3<f64> {
    Point3::new(round_mm(p.x), round_mm(p.y), round_mm(p.z))
}

/// The x-y box of the bounds less `by` on every side (its middle line
/// where it is narrower than that).
fn rectangle_within(b: &Bounds, by: f64) -> Polygon<f64> {
    let shrink = |[lo, hi]: [f64; 2]| {
        if hi - lo > 2.0 * by {
            [lo + by, hi - by]
        } else {
            let mid = (lo + hi) / 2.0;
            [mid, mid + 1e-9]
        }
    };
    rectangle(&Bounds {
        x: shrink(b.x),
        y: shrink(b.y),
        z: b.z,
    })
}

/// The x-y box of the bounds as a polygon.
fn rectangle(b: &Bounds) -> Polygon<f64> {
    let ring = vec![
        Coord {
            x: b.x[0],
            y: b.y[0],
        },
        Coord {
            x: b.x[1],
            y: b.y[0],
        },
        Coord {
            x: b.x[1],
            y: b.y[1],
        },
        Coord {
            x: b.x[0],
            y: b.y[1],
        },
        Coord {
            x: b.x[0],
            y: b.y[0],
        },
    ];
    Polygon::new(LineString::new(ring), Vec::new())
}

/// A polygon's rings in ENU metres; `None` without an outer ring.
fn enu_polygon(
    rings: &[Vec<Position>],
    enu: &dyn Fn(&Position) -> Point2<f64>,
) -> Option<MultiPolygon<f64>> {
    let ring = |r: &Vec<Position>| {
        LineString::new(
            r.iter()
                .map(|p| {
                    let q = enu(p);
                    Coord { x: q.x, y: q.y }
                })
                .collect(),
        )
    };
    let (outer, holes) = rings.split_first()?;
    let polygon = Polygon::new(ring(outer), holes.iter().map(ring).collect());
    Some(MultiPolygon::new(vec![polygon]))
}

/// A ring as a footprint: its vertices to the millimetre (the file shows
/// the short form), without the closing repeat or repeated vertices;
/// `None` when fewer than three remain.
fn footprint_of(ring: &LineString<f64>) -> Option<Vec<Point2<f64>>> {
    let mut out: Vec<Point2<f64>> = Vec::new();
    for c in ring.coords() {
        let p = Point2::new(round_mm(c.x), round_mm(c.y));
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    if out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    (out.len() >= 3).then_some(out)
}

/// The parts of `line` inside `bounds`, their length and the length left
/// outside, metres.
fn clip_line(line: &[Point2<f64>], bounds: &Polygon<f64>) -> (Vec<Vec<Point2<f64>>>, f64, f64) {
    let length = |l: &[Point2<f64>]| l.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>();
    let whole = length(line);
    if line.len() < 2 {
        return (vec![line.to_vec()], 0.0, 0.0);
    }
    let input = MultiLineString::new(vec![LineString::new(
        line.iter().map(|p| Coord { x: p.x, y: p.y }).collect(),
    )]);
    let pieces: Vec<Vec<Point2<f64>>> = bounds
        .clip(&input, false)
        .0
        .into_iter()
        .map(|l| l.coords().map(|c| Point2::new(c.x, c.y)).collect())
        .filter(|l: &Vec<Point2<f64>>| !l.is_empty())
        .collect();
    let inside: f64 = pieces.iter().map(|p| length(p)).sum();
    (pieces, inside, (whole - inside).max(0.0))
}

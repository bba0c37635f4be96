//! A third obstacle shape, written here and nowhere else: a stadium (a
//! segment swept by a radius: a hedge, a parked train, a wall with round
//! ends). It implements `base::shape::Outline` and nothing more, and every
//! planner's geometry kernel reads it right: the solid's clearance, θ-PSO's
//! eq. 4 violation, the route stage's clearance field, the pair queries the
//! IWPs and passages use, the face an inspection looks at, the fleet's eq. 9
//! distance, and the outline drawn and exported. That is the claim of
//! `base::shape`: a new shape is one module.

use nalgebra::{Point2, Point3, Vector2};
use skyform::base::geometry::{segment_point_distance, segment_projection, segments_cross};
use skyform::base::shape::{Footprint, Outline, Polygon, Prism, gap_between, nearest_points};

/// The points within `radius` of the segment `a`-`b`.
#[derive(Debug, Clone)]
struct Stadium {
    a: Point2<f64>,
    b: Point2<f64>,
    radius: f64,
}

impl Stadium {
    fn axis(&self) -> Vector2<f64> {
        (self.b - self.a).normalize()
    }

    /// The point of the spine nearest `q`.
    fn spine(&self, q: &Point2<f64>) -> Point2<f64> {
        let (t, _) = segment_projection(&self.a, &self.b, q);
        self.a + (self.b - self.a) * t
    }

    /// The same stadium as a fine polygon, what the kernels' answers are
    /// checked against.
    fn polygon(&self, tolerance: f64) -> Polygon {
        Polygon::new(self.ring(tolerance))
    }
}

impl Outline for Stadium {
    fn kind(&self) -> &'static str {
        "stadium"
    }

    fn bounding_circle(&self) -> (Point2<f64>, f64) {
        let c = nalgebra::center(&self.a, &self.b);
        (c, (self.b - c).norm() + self.radius)
    }

    fn signed_distance(&self, q: &Point2<f64>) -> f64 {
        segment_point_distance(&self.a, &self.b, q) - self.radius
    }

    fn nearest(&self, q: &Point2<f64>) -> Point2<f64> {
        let s = self.spine(q);
        let away = q - s;
        let out = if away.norm() > 0.0 {
            away.normalize()
        } else {
            let u = self.axis();
            Vector2::new(-u.y, u.x)
        };
        s + out * self.radius
    }

    fn segment_distance(&self, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
        let spine = if segments_cross(a, b, &self.a, &self.b) {
            0.0
        } else {
            [
                segment_point_distance(a, b, &self.a),
                segment_point_distance(a, b, &self.b),
                segment_point_distance(&self.a, &self.b, a),
                segment_point_distance(&self.a, &self.b, b),
            ]
            .into_iter()
            .fold(f64::INFINITY, f64::min)
        };
        let ends = self.signed_distance(a).min(self.signed_distance(b));
        if ends <= 0.0 {
            ends
        } else {
            (spine - self.radius).max(0.0)
        }
    }

    fn normal(&self, q: &Point2<f64>) -> Vector2<f64> {
        let on = self.nearest(q);
        on - self.spine(&on)
    }

    fn nearest_to_line(&self, on: &Point2<f64>, n: &Vector2<f64>) -> (Point2<f64>, f64) {
        let end = if (self.a - self.b).dot(n) >= 0.0 {
            self.a
        } else {
            self.b
        };
        let p = end + n * self.radius;
        (p, (on - p).dot(n))
    }

    /// Anticlockwise: along one side, round the far end, back, round the
    /// near end; each half circle in as many chords as keep `tolerance`.
    fn ring(&self, tolerance: f64) -> Vec<Point2<f64>> {
        let u = self.axis();
        let heading = u.y.atan2(u.x);
        let half = (1.0 - (tolerance / self.radius).min(1.0)).acos().max(1e-3);
        let n = ((std::f64::consts::PI / (2.0 * half)).ceil() as usize).max(4);
        let arc = |c: Point2<f64>, from: f64| {
            (0..=n).map(move |k| {
                let t = from + std::f64::consts::PI * k as f64 / n as f64;
                c + Vector2::new(t.cos(), t.sin()) * self.radius
            })
        };
        let right = heading - std::f64::consts::FRAC_PI_2;
        arc(self.b, right)
            .chain(arc(self.a, right + std::f64::consts::PI))
            .collect()
    }

    fn words(&self) -> String {
        format!(
            "stadium {:.1} m long, radius {} m",
            (self.b - self.a).norm(),
            self.radius
        )
    }
}

/// A hedge 20 m long along x, 1.5 m round its spine, 4 m high.
fn hedge() -> Stadium {
    Stadium {
        a: Point2::new(0.0, 0.0),
        b: Point2::new(20.0, 0.0),
        radius: 1.5,
    }
}

#[test]
fn the_solid_of_a_new_shape_is_cleared_beside_over_and_inside() {
    let prism = Prism::new(Footprint::new(hedge()), 0.0, 4.0);
    assert_eq!(prism.center, Point2::new(10.0, 0.0));
    assert_eq!(prism.radius, 11.5);
    // Beside the middle of its side, past its round end, inside, over it.
    assert_eq!(prism.clearance(&Point3::new(10.0, 3.5, 2.0)), 2.0);
    assert_eq!(prism.clearance(&Point3::new(23.5, 0.0, 2.0)), 2.0);
    assert_eq!(prism.clearance(&Point3::new(5.0, 0.5, 2.0)), -1.0);
    assert_eq!(prism.clearance(&Point3::new(10.0, 0.0, 7.0)), 3.0);
    let past = prism.clearance(&Point3::new(10.0, 5.5, 7.0));
    assert!((past - 5.0).abs() < 1e-12, "3-4-5 over its side: {past}");
    // Its bounding circle's broad phase holds it.
    for p in hedge().ring(0.01) {
        assert!((p - prism.center).norm() <= prism.radius + 1e-9);
    }
}

#[test]
fn theta_pso_eq4_violation_along_a_leg_is_the_shapes_own() {
    use skyform::pipelines::theta_pso::cost::violation_along;
    // A level leg 2.4 m beside the hedge's side, for r_Q + margin = 3 m:
    // the same integral as for the hedge drawn as a polygon at 1 mm.
    let (p, q) = (Point3::new(-5.0, 3.9, 2.0), Point3::new(25.0, 3.9, 2.0));
    let stadium = Prism::new(Footprint::new(hedge()), 0.0, 4.0);
    let polygon = Prism::new(Footprint::new(hedge().polygon(0.001)), 0.0, 4.0);
    let safe = stadium.radius + 3.0;
    let exact = violation_along(&p, &q, &stadium, safe);
    let drawn = violation_along(&p, &q, &polygon, safe);
    assert!(exact > 0.0, "the leg passes within r_Q + margin");
    assert!(
        (exact - drawn).abs() < 1e-3 * exact,
        "{exact} vs {drawn} (polygon at 1 mm)"
    );
    // Clear of it by more than the margin: nothing.
    let far = violation_along(
        &Point3::new(-5.0, 8.0, 2.0),
        &Point3::new(25.0, 8.0, 2.0),
        &stadium,
        safe,
    );
    assert_eq!(far, 0.0);
}

#[test]
fn the_route_stages_clearance_field_reads_a_new_shape() {
    use skyform::pipelines::theta_pso::route::field::Field;
    let shapes = [Footprint::new(hedge())];
    let field = Field::new([[-10.0, 30.0], [-10.0, 10.0]], &shapes, 0.25, 20.0);
    for p in [
        Point2::new(10.0, 4.0),
        Point2::new(24.0, 1.0),
        Point2::new(-3.0, -3.0),
    ] {
        let cell = field.index_of(p);
        let at = field.center(cell);
        let expected = hedge().signed_distance(&at);
        assert!(
            (f64::from(field.clearance(cell) as f32) - expected).abs() < 1e-5,
            "at {at}: {} vs {expected}",
            field.clearance(cell)
        );
        assert!((field.clearance_at(p, &shapes) - hedge().signed_distance(&p)).abs() < 1e-12);
    }
}

#[test]
fn the_pair_queries_find_the_passage_beside_a_new_shape() {
    // A pole 4 m off the hedge's side: a 2.5 m passage between them, its
    // ends where the IWP of eq. 9 is placed (the middle of P_p, P_q).
    let pole = Footprint::circle(Point2::new(8.0, 5.0), 1.0);
    let h = Footprint::new(hedge());
    assert!((gap_between(&*h, &*pole) - 2.5).abs() < 1e-9);
    let (on_hedge, on_pole) = nearest_points(&*h, &*pole);
    assert!(
        (on_hedge - Point2::new(8.0, 1.5)).norm() < 1e-9,
        "{on_hedge}"
    );
    assert!((on_pole - Point2::new(8.0, 4.0)).norm() < 1e-9, "{on_pole}");
    // Two hedges end to end, 3 m between their round ends: no corners,
    // no disc; found by the shapes' own projections.
    let next = Footprint::new(Stadium {
        a: Point2::new(26.0, 0.0),
        b: Point2::new(40.0, 0.0),
        radius: 1.5,
    });
    assert!((gap_between(&*h, &*next) - 3.0).abs() < 1e-6);
    let (p, q) = nearest_points(&*h, &*next);
    assert!(
        (p - Point2::new(21.5, 0.0)).norm() < 1e-6 && (q - Point2::new(24.5, 0.0)).norm() < 1e-6
    );
}

#[test]
fn the_face_an_inspection_looks_at_is_the_new_shapes_own() {
    use skyform::pipelines::verify::{face_bearing, on_side};
    let prism = Prism::new(Footprint::new(hedge()), 0.0, 4.0);
    // North of its side it faces north; past its east end, east.
    let north = face_bearing(&prism, &Point3::new(10.0, 4.0, 2.0));
    let east = face_bearing(&prism, &Point3::new(25.0, 0.0, 2.0));
    assert!(
        north.abs() < 1e-9 || (north - 360.0).abs() < 1e-9,
        "{north}"
    );
    assert!((east - 90.0).abs() < 1e-9, "{east}");
    assert!(on_side(&prism, &Point3::new(10.0, 4.0, 2.0), 0.0));
    assert!(!on_side(&prism, &Point3::new(10.0, -4.0, 2.0), 0.0));
}

#[test]
fn the_fleets_eq9_distance_is_to_the_new_shapes_nearest_point() {
    use skyform::pipelines::fleet::cost::{Observation, obstacle_penalty};
    let view = |position: Point2<f64>| Observation {
        position,
        target: Point2::new(10.0, 20.0),
        target_distance: 0.0,
        neighbours: Vec::new(),
        obstacles: vec![Footprint::new(hedge())],
        rho: 1.0,
        safety: 0.8,
        sigma: 0.4,
        keep_apart: 0.0,
        keep_clear: 0.0,
    };
    // 0.8 m off the side (c): eq. 9's penalty is 1; the step's cost is
    // the distance to the target plus it.
    let at_c = Point2::new(10.0, 2.3);
    let cost = view(at_c).cost(&Vector2::zeros());
    let expected = (Point2::new(10.0, 20.0) - at_c).norm() + obstacle_penalty(0.8, 0.8, 0.4);
    assert!((cost - expected).abs() < 1e-9, "{cost} vs {expected}");
    assert!((obstacle_penalty(0.8, 0.8, 0.4) - 1.0).abs() < 1e-12);
}

#[test]
fn the_outline_drawn_and_exported_keeps_its_tolerance() {
    let h = hedge();
    for tolerance in [0.1, 0.01] {
        let ring = h.ring(tolerance);
        for (i, p) in ring.iter().enumerate() {
            assert!(h.signed_distance(p).abs() < 1e-9, "on the outline");
            let q = ring[(i + 1) % ring.len()];
            let stray = -h.signed_distance(&nalgebra::center(p, &q));
            assert!(stray <= tolerance + 1e-9, "{stray} > {tolerance}");
        }
        // Anticlockwise, as KML's outer boundary and the mesh caps want.
        let area: f64 = (0..ring.len())
            .map(|i| ring[i].coords.perp(&ring[(i + 1) % ring.len()].coords))
            .sum();
        assert!(area > 0.0);
    }
    assert_eq!(h.words(), "stadium 20.0 m long, radius 1.5 m");
}

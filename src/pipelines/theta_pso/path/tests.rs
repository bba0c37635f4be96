use super::*;

/// The paper's triangle (Fig. 2's formation), r_Q = 0.5 m.
fn triangle() -> Vec<Vector3<f64>> {
    vec![
        Vector3::new(2.0, 0.0, 0.0),
        Vector3::new(-1.0, 2.0, 0.0),
        Vector3::new(-1.0, -2.0, 0.0),
    ]
}

fn zone(iwp: usize, shape: Shape, hold: [f64; 2], transition: f64) -> Zone {
    Zone {
        causes: vec![ZoneCause::Iwp {
            iwp,
            pair: [2 * iwp, 2 * iwp + 1],
        }],
        shape,
        arc: (hold[0] + hold[1]) / 2.0,
        hold,
        transition_in: transition,
        transition_out: transition,
        from: None,
        into: None,
    }
}

const HALF: Shape = Shape::Shrink { scale: 0.5 };
const COLUMN: Shape = Shape::Alignment { spacing: 2.0 };

/// Eq. 9 / Fig. 2 read for one IWP: room for both changes between two
/// zones, and each returns to the nominal shape on its own.
#[test]
fn zones_with_room_between_them_each_return_to_the_nominal_shape() {
    let zones = vec![
        zone(1, Shape::Rotation, [60.0, 64.0], 5.0),
        zone(0, HALF, [20.0, 24.0], 5.0),
    ];
    let out = schedule(zones, &triangle(), 0.5);
    assert_eq!(out.len(), 2);
    assert_eq!(out[0].shape, HALF, "sorted along the path");
    assert!(out.iter().all(|z| z.from.is_none() && z.into.is_none()));
    assert_eq!(out[0].transition_out, 5.0);
}

/// Two rigid shapes closer than their changes need, but at least
/// `MIN_BLEND` apart: the change out of the first ends in the second,
/// over the whole stretch between the holds, and the shape is continuous
/// there (no return to the nominal shape between them).
#[test]
fn close_zones_blend_straight_from_one_shape_into_the_next() {
    let slots = triangle();
    let zones = vec![
        zone(0, HALF, [20.0, 24.0], 5.0),
        zone(1, Shape::Rotation, [28.0, 32.0], 5.0),
    ];
    let out = schedule(zones, &slots, 0.5);
    assert_eq!(out.len(), 2);
    assert_eq!(out[0].into, Some(Shape::Rotation));
    assert_eq!(out[1].from, Some(HALF));
    assert_eq!(out[0].transition_out, 4.0);
    assert_eq!(out[1].transition_in, 4.0);
    // One change, seen from both zones: the first's change out is the
    // second's change in, [24, 28].
    assert_eq!(out[0].arcs()[2..], out[1].arcs()[..2]);
    // Halfway between the holds the formation is halfway from one
    // shape to the other.
    let (Some(a), Some(b)) = (out[0].state(26.0), out[1].state(26.0)) else {
        panic!("both zones cover the stretch between their holds");
    };
    for n in 0..slots.len() {
        let mid = HALF
            .offset(&slots, n, 1.0)
            .lerp(&Shape::Rotation.offset(&slots, n, 1.0), 0.5);
        assert!((a.offset(&slots, n) - mid).norm() < 1e-12);
        assert!((b.offset(&slots, n) - mid).norm() < 1e-12);
    }
    // Never the nominal shape in between.
    for s in [24.5, 25.0, 27.0, 27.5] {
        let state = out[0].state(s).or(out[1].state(s));
        assert!(state.is_some_and(|st| st.from.is_some() && st.to.is_some()));
    }
}

/// Closer than `MIN_BLEND` (here the holds overlap): one hold over both
/// in the narrower shape, which fits both gaps, with both causes kept.
#[test]
fn overlapping_zones_become_one_hold_in_the_narrower_shape() {
    let zones = vec![
        zone(0, Shape::Shrink { scale: 0.8 }, [20.0, 24.0], 5.0),
        zone(1, HALF, [23.0, 27.0], 5.0),
    ];
    let out = schedule(zones, &triangle(), 0.5);
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].shape, HALF);
    assert_eq!(out[0].hold, [20.0, 27.0]);
    assert_eq!(out[0].causes.len(), 2);
    assert!(out[0].from.is_none() && out[0].into.is_none());
}

/// The column never blends with a spread shape (a straight blend can
/// bring two UAVs closer than either shape): even with room for a blend
/// the two holds join, in the column.
#[test]
fn a_column_takes_over_a_close_neighbour() {
    let zones = vec![
        zone(0, HALF, [20.0, 24.0], 5.0),
        zone(1, COLUMN, [28.0, 32.0], 5.0),
    ];
    let out = schedule(zones, &triangle(), 0.5);
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].shape, COLUMN);
    assert_eq!(out[0].hold, [20.0, 32.0]);
}

/// Three in a row: the second and third join, and the first, which
/// blended into the second's shape, now blends into the joined hold's.
#[test]
fn a_join_updates_the_blend_of_the_zone_before() {
    let zones = vec![
        zone(0, Shape::Rotation, [10.0, 14.0], 5.0),
        zone(1, Shape::Shrink { scale: 0.8 }, [18.0, 22.0], 5.0),
        zone(2, HALF, [22.5, 26.0], 5.0),
    ];
    let out = schedule(zones, &triangle(), 0.5);
    assert_eq!(out.len(), 2);
    assert_eq!(out[1].shape, HALF);
    assert_eq!(out[1].hold, [18.0, 26.0]);
    assert_eq!(out[0].into, Some(HALF));
    assert_eq!(out[1].from, Some(Shape::Rotation));
}

/// The squeezed stretches are only sampled where a leg is inside the
/// regions' box: the share the clip returns is exactly the part inside.
#[test]
fn a_leg_is_clipped_to_the_part_inside_the_box() {
    use super::squeeze::clip;
    let unit = [Point2::new(0.0, 0.0), Point2::new(1.0, 1.0)];
    // Through the middle, from x = -1 to x = 3 at y = 0.5: inside for x in [0, 1].
    let through = clip(Point2::new(-1.0, 0.5), Point2::new(3.0, 0.5), unit);
    assert_eq!(through, Some([0.25, 0.5]));
    // Wholly inside: all of it.
    assert_eq!(
        clip(Point2::new(0.2, 0.2), Point2::new(0.8, 0.9), unit),
        Some([0.0, 1.0])
    );
    // Parallel to a side and outside it, and a diagonal that passes the corner.
    assert_eq!(
        clip(Point2::new(-1.0, 2.0), Point2::new(3.0, 2.0), unit),
        None
    );
    assert_eq!(
        clip(Point2::new(1.5, 0.0), Point2::new(3.0, 1.5), unit),
        None
    );
    // A leg that ends inside: from its entry to its end.
    let [u0, u1] = clip(Point2::new(0.5, -1.0), Point2::new(0.5, 0.5), unit).unwrap_or_default();
    assert!((u0 - 2.0 / 3.0).abs() < 1e-12 && u1 == 1.0, "{u0} {u1}");
}

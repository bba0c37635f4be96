use super::*;
use crate::mission::default_mission;

#[test]
fn every_field_reads_back_what_it_writes() {
    let mut m = default_mission().mission;
    let items = [
        Item::Bounds,
        Item::Start,
        Item::Obstacle(0),
        Item::Formation,
        Item::Slot(1),
        Item::Section(Kind::ThetaPso),
    ];
    for item in items {
        for (k, f) in fields(&item, &m).into_iter().enumerate() {
            let value = match f.label() {
                l if l.contains("shape") => "shrink".to_string(),
                "preset" => "diamond".to_string(),
                "cost" => "paper".to_string(),
                "encoding" => "angle".to_string(),
                _ if f.value() == "yes" || f.value() == "no" => "yes".to_string(),
                l if l.ends_with("lat (°)") || l.ends_with("lon (°)") => {
                    // A position nearby: 7° would be thousands of km off the site.
                    let now: f64 = f.value().parse().unwrap();
                    let typed = format!("{:.8}", now + 1e-4);
                    typed.trim_end_matches('0').trim_end_matches('.').to_owned()
                }
                _ => "7".to_string(),
            };
            f.set(&mut m, &item, &value).unwrap();
            assert_eq!(
                fields(&item, &m)[k].value(),
                value,
                "{item:?} {}",
                f.label()
            );
        }
    }
}

#[test]
fn bad_text_is_refused_with_what_was_expected() {
    let mut m = default_mission().mission;
    let all = fields(&Item::Obstacle(0), &m);
    let radius = all.iter().find(|f| f.label() == "radius (m)").unwrap();
    let before = m.clone();
    let err = radius.set(&mut m, &Item::Obstacle(0), "wide").unwrap_err();
    assert_eq!(err, "'wide' is not a number");
    assert_eq!(m, before);
    assert!(radius.set(&mut m, &Item::Obstacle(0), "NaN").is_err());
}

#[test]
fn an_iwp_choice_is_created_on_first_edit() {
    let mut m = default_mission().mission;
    m.reconfiguration.waypoints.clear();
    let item = Item::Waypoint(["pier 5".into(), "light pole 4".into()]);
    let shape = &fields(&item, &m)[2];
    assert_eq!(shape.label(), "shape");
    assert!(shape.set(&mut m, &item, "round").is_err());
    assert!(
        m.reconfiguration.waypoints.is_empty(),
        "not on a refused text"
    );
    shape.set(&mut m, &item, "rotation").unwrap();
    assert_eq!(m.reconfiguration.waypoints.len(), 1);
    assert_eq!(m.reconfiguration.waypoints[0].shape, ShapeChoice::Rotation);
    // Named the other way round, it is the same IWP.
    let item = Item::Waypoint(["light pole 4".into(), "pier 5".into()]);
    fields(&item, &m)[1].set(&mut m, &item, "no").unwrap();
    assert_eq!(m.reconfiguration.waypoints.len(), 1);
    assert!(!m.reconfiguration.waypoints[0].enabled);
}

/// The label of the field (or of the last field of the group) a
/// message holding `message` is drawn under for `item`; "item" when it
/// is drawn with the item.
fn shown_under(item: &Item, m: &Mission, message: &str) -> Option<String> {
    let fields = fields(item, m);
    let d = crate::outcome::diagnose::diagnose(m)
        .into_iter()
        .find(|d| d.message.contains(message))?;
    let (place, _) = place(item, m, &fields, &d.path)?;
    Some(match place.after() {
        Some(k) => fields[k].label().to_owned(),
        None => "item".to_owned(),
    })
}

/// A message on one element of an array is under that element's field;
/// one on the whole array after the group of its elements; an IWP's own
/// entry's messages are under the IWP, and an IWP without an entry
/// claims none.
#[test]
fn each_message_is_under_the_field_it_names() {
    let mut m = default_mission().mission;
    m.obstacles[3].stand_off = Some([1.0, f64::NAN]);
    assert_eq!(
        shown_under(&Item::Obstacle(3), &m, "finite").as_deref(),
        Some("stand-off max (m)")
    );
    m.obstacles[3].stand_off = Some([1.0, 5.0]);
    m.route.start.z = f64::INFINITY;
    assert_eq!(
        shown_under(&Item::Start, &m, "finite").as_deref(),
        Some("z (m)")
    );
    // Issue 24, item 6: the start's altitude out of the band is under z.
    m.route.start.z = 50.0;
    assert_eq!(
        shown_under(&Item::Start, &m, "altitude band").as_deref(),
        Some("z (m)")
    );
    m.route.start.z = 10.0;
    // An inverted range is about both ends: after the pair.
    m.bounds.x = [150.0, 100.0];
    let bounds = fields(&Item::Bounds, &m);
    let d = crate::outcome::diagnose::diagnose(&m);
    let whole = d
        .iter()
        .find(|d| d.path.to_string() == "bounds.x")
        .expect("a message on bounds.x");
    assert_eq!(
        place(&Item::Bounds, &m, &bounds, &whole.path),
        Some((Place::Group(0, 1), true))
    );
    // Issue 24, item 6: 1e9 typed into x max is a message under x max.
    m.bounds.x = [0.0, 1e9];
    assert_eq!(
        shown_under(&Item::Bounds, &m, "local plane").as_deref(),
        Some("x max (m)")
    );
    m.bounds.x = [0.0, 138.0];

    // An IWP entry naming a missing obstacle: its message is under the
    // IWP's obstacles field, and the IWP without an entry claims none.
    let iwp = Item::Waypoint(["pier 5".into(), "light pole 4".into()]);
    m.reconfiguration.waypoints.clear();
    m.reconfiguration.waypoints.push(WaypointChoice {
        between: ["pier 5".into(), "nowhere".into()],
        enabled: true,
        shape: ShapeChoice::Auto,
        scale: None,
    });
    let broken = Item::Waypoint(["pier 5".into(), "nowhere".into()]);
    let d = crate::outcome::diagnose::diagnose(&m);
    let between = d
        .iter()
        .find(|d| d.path.to_string() == "reconfiguration.waypoints[0].between")
        .expect("a message on the missing name");
    assert!(place(&iwp, &m, &fields(&iwp, &m), &between.path).is_none());
    let broken_fields = fields(&broken, &m);
    let (at, exact) = place(&broken, &m, &broken_fields, &between.path).unwrap();
    assert!(exact);
    assert_eq!(broken_fields[at.after().unwrap()].label(), "obstacles");
    assert!(iwp.path(&m).is_none());
}

/// Issue 24, item 6: a number too large for a double is not "not a number".
#[test]
fn a_number_too_large_says_so() {
    assert!(number("1e400").unwrap_err().contains("too large"));
    assert!(number("-1e400").unwrap_err().contains("too large"));
    assert_eq!(number("inf").unwrap_err(), "'inf' is not a number");
    assert_eq!(number("1e9"), Ok(1e9));
}

/// Issue 13: a field's path is the typed path the validator reports on.
#[test]
fn each_field_is_at_the_typed_path_its_diagnostics_name() {
    let mut m = default_mission().mission;
    let at = |item: &Item, m: &Mission, label: &str| {
        let f = fields(item, m).into_iter().find(|f| f.label() == label);
        f.map(|f| f.path().to_string())
    };
    let obstacle = Item::Obstacle(3);
    assert_eq!(
        at(&obstacle, &m, "radius (m)").as_deref(),
        Some("obstacles[3].radius")
    );
    assert_eq!(
        at(&obstacle, &m, "stand-off max (m)").as_deref(),
        Some("obstacles[3].stand_off[1]")
    );
    assert_eq!(
        at(&Item::Start, &m, "z (m)").as_deref(),
        Some("route.start[2]")
    );
    assert_eq!(
        at(&Item::Formation, &m, "default shape").as_deref(),
        Some("reconfiguration.default_shape")
    );
    assert_eq!(
        at(&Item::Slot(2), &m, "up z (m)").as_deref(),
        Some("formation.slots[2][2]")
    );
    // An IWP without an entry yet: where its entry will go.
    m.reconfiguration.waypoints.clear();
    let iwp = Item::Waypoint(["pier 5".into(), "light pole 4".into()]);
    assert_eq!(
        at(&iwp, &m, "shape").as_deref(),
        Some("reconfiguration.waypoints[0].shape")
    );
    fields(&iwp, &m)[2].set(&mut m, &iwp, "shrink").unwrap();
    assert_eq!(
        at(&iwp, &m, "shape").as_deref(),
        Some("reconfiguration.waypoints[0].shape")
    );

    // The validator's message on the radius is the radius field's.
    m.obstacles[3].radius = -1.0;
    let all = fields(&obstacle, &m);
    let radius = all.iter().find(|f| f.label() == "radius (m)").unwrap();
    let found: Vec<_> = crate::outcome::diagnose::diagnose(&m)
        .into_iter()
        .filter(|d| d.path.starts_with(radius.path()))
        .collect();
    assert!(
        found.iter().any(|d| d.message.contains("must be positive")),
        "{found:?}"
    );
    assert_eq!(radius.unit(), "m");
    // A missing item has no fields.
    assert!(fields(&Item::Obstacle(99), &m).is_empty());
}

#[test]
fn numbers_are_shown_as_typed() {
    assert_eq!(fmt_num(3.0), "3");
    assert_eq!(fmt_num(-0.0), "0");
    assert_eq!(fmt_num(0.7298), "0.7298");
    assert_eq!(fmt_num(1e5), "100000");
    assert_eq!(fmt_num(2.71), "2.71", "short values exactly");
    assert_eq!(fmt_num(12.345678), "12.345678");
    assert_eq!(fmt_num(0.1 + 0.2), "0.3", "long ones rounded");
}

/// A pipeline's section's rows (its face's) are at their paths in the
/// file, an array's elements indexed as the validator indexes them, so a
/// message on `flatlo.start[1]` is shown under "start y".
#[test]
fn a_sections_rows_are_at_their_paths_elements_indexed() {
    let m = default_mission().mission;
    let path_of = |kind: Kind, label: &str| {
        fields(&Item::Section(kind), &m)
            .into_iter()
            .find(|f| f.label().starts_with(label))
            .map(|f| f.path().to_string())
    };
    assert_eq!(
        path_of(Kind::Flatlo, "start x").as_deref(),
        Some("flatlo.start[0]")
    );
    assert_eq!(
        path_of(Kind::Flatlo, "start y").as_deref(),
        Some("flatlo.start[1]")
    );
    assert_eq!(
        path_of(Kind::Flatlo, "PID kd").as_deref(),
        Some("flatlo.pid[2]")
    );
    assert_eq!(
        path_of(Kind::Fleet, "inertia J z").as_deref(),
        Some("fleet.inertia_diag[2]")
    );
    assert_eq!(
        path_of(Kind::Fleet, "agents n").as_deref(),
        Some("fleet.agents")
    );
    assert_eq!(
        path_of(Kind::ThetaPso, "swarm size").as_deref(),
        Some("theta_pso.swarm_size")
    );
}

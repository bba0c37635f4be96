//! Saving keeps the user's file: unchanged missions round-trip byte for
//! byte, a change touches only its own line, defaults the file did not
//! write stay unwritten, and what is written reads back as the mission.

use skyform::mission::{self, BUILTIN, Mission, Obstacle, edit_in_place};

fn parse(text: &str) -> Mission {
    toml::from_str(text).expect("a mission")
}

fn changed_lines(a: &str, b: &str) -> Vec<(usize, String, String)> {
    assert_eq!(
        a.lines().count(),
        b.lines().count(),
        "line count changed:\n{b}"
    );
    a.lines()
        .zip(b.lines())
        .enumerate()
        .filter(|(_, (x, y))| x != y)
        .map(|(i, (x, y))| (i + 1, x.to_owned(), y.to_owned()))
        .collect()
}

#[test]
fn every_shipped_mission_saves_back_byte_for_byte() {
    for b in BUILTIN {
        let m = parse(b.text);
        let saved = edit_in_place(&m, b.text).expect("a mission file");
        assert_eq!(
            saved, b.text,
            "{} changed on an unchanged save",
            b.file_name
        );
    }
}

#[test]
fn changing_one_radius_changes_exactly_that_line() {
    for b in BUILTIN {
        let mut m = parse(b.text);
        if m.obstacles.len() < 2 {
            continue;
        }
        let k = m.obstacles.len() / 2;
        m.obstacles[k].radius += 0.25;
        let saved = edit_in_place(&m, b.text).unwrap();
        let changed = changed_lines(b.text, &saved);
        assert_eq!(changed.len(), 1, "{}: {changed:?}", b.file_name);
        let (_, before, after) = &changed[0];
        assert!(before.trim_start().starts_with("radius"), "{before}");
        assert!(after.trim_start().starts_with("radius"), "{after}");
        assert_eq!(parse(&saved), m);
    }
}

/// A comment after a value stays when the value changes.
#[test]
fn a_changed_value_keeps_its_comment_and_spacing() {
    let text = "name = \"t\"\n\n[bounds]\nx = [0.0, 40.0]   # east\ny = [0.0, 30.0]\nz = [1.0, 9.0]\n\n\
                [route]\nstart = [5.0, 15.0, 5.0]\ngoal = [35.0, 15.0, 5.0]\n";
    let mut m = parse(text);
    m.bounds.x = [0.0, 50.0];
    let saved = edit_in_place(&m, text).unwrap();
    assert!(saved.contains("x = [0.0, 50.0]   # east\n"), "{saved}");
    assert_eq!(parse(&saved), m);
}

#[test]
fn defaults_the_file_did_not_write_stay_unwritten() {
    let text = BUILTIN
        .iter()
        .find(|b| b.file_name == "narrow-passage.toml")
        .unwrap()
        .text;
    assert!(!text.contains("[flatlo]") && !text.contains("weight_turning"));
    let mut m = parse(text);
    m.theta_pso.weight_turning = 12.5;
    let saved = edit_in_place(&m, text).unwrap();
    // Only the changed default is added, in its own section.
    assert!(!saved.contains("[flatlo]"), "{saved}");
    assert!(!saved.contains("[fleet]"), "{saved}");
    let added: Vec<&str> = saved.lines().filter(|l| !text.contains(*l)).collect();
    assert_eq!(added, ["weight_turning = 12.5"], "{saved}");
    assert_eq!(parse(&saved), m);
}

#[test]
fn a_new_obstacle_and_a_deleted_one_read_back() {
    let b = &BUILTIN[0];
    let mut m = parse(b.text);
    let mut o: Obstacle = m.obstacles[0].clone();
    o.name = "new pier".into();
    o.center.x += 3.0;
    m.obstacles.push(o);
    let saved = edit_in_place(&m, b.text).unwrap();
    assert!(
        saved.starts_with(&b.text[..200]),
        "the head of the file stays"
    );
    assert!(saved.contains("name = \"new pier\""));
    assert_eq!(parse(&saved), m);
    m.obstacles.remove(1);
    let saved2 = edit_in_place(&m, &saved).unwrap();
    assert_eq!(parse(&saved2), m);
    assert!(saved2.lines().count() < saved.lines().count());
}

#[test]
fn a_section_the_file_lacked_is_added_with_only_the_changed_keys() {
    let b = BUILTIN
        .iter()
        .find(|b| b.file_name == "narrow-passage.toml")
        .unwrap();
    let mut m = parse(b.text);
    m.flatlo.aircraft = 6;
    let saved = edit_in_place(&m, b.text).unwrap();
    assert!(saved.contains("[flatlo]\naircraft = 6\n"), "{saved}");
    assert_eq!(
        saved.matches(" = ").count(),
        b.text.matches(" = ").count() + 1
    );
    assert_eq!(parse(&saved), m);
}

#[test]
fn save_edited_writes_atomically_and_returns_the_text() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.toml");
    let b = &BUILTIN[1];
    let mut m = parse(b.text);
    m.formation.ground_speed = 2.5;
    let text = mission::save_edited(&m, Some(b.text), &path).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
    assert_eq!(changed_lines(b.text, &text).len(), 1);
    // No temporary file is left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// A new item is written one key per line in the model's order.
#[test]
fn a_new_obstacle_is_written_like_the_others() {
    let b = &BUILTIN[1];
    let mut m = parse(b.text);
    let mut o = m.obstacles[0].clone();
    o.name = "new".into();
    m.obstacles.push(o);
    let saved = edit_in_place(&m, b.text).unwrap();
    let tail = &saved[saved.rfind("[[obstacles]]").unwrap()..];
    assert_eq!(
        tail,
        "[[obstacles]]\nname = \"new\"\ncenter = [20.0, 7.0]\nradius = 7.0\nheight = 20.0\nkind = \"wall\"\n"
    );
}

/// Issue 24, item 18: a section the file lacked (an [origin] removed, then
/// set again) goes where the model has it, before [bounds], not after the
/// obstacles at the end of the file.
#[test]
fn a_section_added_again_goes_where_the_model_has_it() {
    let text = BUILTIN[0].text;
    let mut m = parse(text);
    let origin = m.origin.take().expect("the bridge has an origin");
    let without = edit_in_place(&m, text).unwrap();
    assert!(!without.contains("[origin]"), "{without}");
    m.origin = Some(origin);
    let again = edit_in_place(&m, &without).unwrap();
    let at = |section: &str| {
        again
            .find(section)
            .unwrap_or_else(|| panic!("no {section} in\n{again}"))
    };
    assert!(at("[origin]") < at("[bounds]"), "{again}");
    assert!(at("[origin]") > at("seed ="), "{again}");
    assert_eq!(parse(&again), m);
}

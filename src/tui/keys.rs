//! The key table the help overlay, the hints and the README show. Its own
//! module so the views read it without importing the input handling (which
//! imports the views for hit-testing).

/// Every key, grouped as the help overlay shows them: (group, keys, what).
pub const KEYS: &[(&str, &str, &str)] = &[
    (
        "General",
        "?",
        "this help (↑ ↓ PgUp PgDn scroll it on a small screen)",
    ),
    (
        "General",
        "q  Ctrl-c",
        "quit (asks when there are unsaved changes)",
    ),
    ("General", "Tab  Shift-Tab", "focus map → inspector → jobs"),
    ("General", "1  2", "map / formation editor"),
    (
        "General",
        "v",
        "side view: distance along the path vs altitude",
    ),
    ("General", "u  Ctrl-z", "undo"),
    ("General", "Ctrl-r  Ctrl-y", "redo"),
    (
        "General",
        "Ctrl-s",
        "save (atomic, into your file); W save as (Ctrl-u clears the name); o open (type to filter the list or give any path)",
    ),
    (
        "Select & move",
        "n  p",
        "next / previous item (map: mission, bounds, start, goal, obstacles, θ-PSO; formation: slots, IWPs)",
    ),
    (
        "Select & move",
        "← → ↑ ↓",
        "nudge the selection one step (map & formation focus)",
    ),
    ("Select & move", "[  ]", "smaller / larger nudge step"),
    ("Select & move", "+  -  0", "zoom in / out / fit"),
    ("Select & move", "Shift-arrows", "pan the map"),
    (
        "Select & move",
        "mouse",
        "click selects, drag moves, wheel zooms",
    ),
    (
        "Edit",
        "a",
        "add an obstacle at the view's centre (formation: add a slot)",
    ),
    (
        "Edit",
        "A",
        "add tool: click an empty spot to place an obstacle",
    ),
    ("Edit", "d", "duplicate the selected obstacle"),
    (
        "Edit",
        "i",
        "inspect the selected obstacle (eq. 8) or stop inspecting it",
    ),
    (
        "Edit",
        "Del  D",
        "delete the selected obstacle / slot / IWP choice",
    ),
    (
        "Edit",
        "Enter",
        "edit the field (inspector); type a number to replace it; Enter applies",
    ),
    (
        "Edit",
        "Esc",
        "cancel typing, close a window, leave the add tool",
    ),
    (
        "Formation",
        "P",
        "apply the next preset: triangle, line abreast, column, V, diamond",
    ),
    (
        "Formation",
        "s  Space",
        "cycle the IWP's shape / enable or disable it",
    ),
    ("Run", "r", "run θ-PSO with the mission's seed"),
    (
        "Run",
        "F",
        "run FLATLO, the squadron transition (select Squadron with n/p to edit it)",
    ),
    (
        "Run",
        "T",
        "run the distributed fleet (select Fleet and its targets with n/p to edit them; d adds a target)",
    ),
    (
        "Run",
        ",  .  >",
        "fleet replay: back / forward one second, play or pause",
    ),
    ("Run", "N", "re-run the last pipeline with a new seed"),
    ("Run", "x", "cancel the selected (or latest) running job"),
    (
        "Run",
        "Enter",
        "jobs focus: show that job's result on the map",
    ),
    (
        "Run",
        "e  E",
        "record runs to .rrd beside the mission / Rerun viewer: off, connect, spawn",
    ),
    (
        "Run",
        "X",
        "export the shown result per vehicle (.plan, .waypoints, CSV) to <mission>-export/",
    ),
];

//! The help overlay: the key table (`tui::keys`) in one column, or in two
//! balanced ones when the screen is wide, each key's words hanging under
//! its description.

use ratatui::Frame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Clear, Paragraph, Wrap};

use super::{boxed, centred, key, rows};
use crate::tui::app::App;
use crate::tui::keys::{KEYS, KeyRow};

/// The key table, in two columns when there is room; it scrolls when taller than the screen.
pub(super) fn draw_help(frame: &mut Frame, app: &App, area: Rect) {
    // Two columns when there is room, else one (the README lists every key too).
    let groups = ["General", "Select & move", "Edit", "Formation", "Run"];
    let wide = area.width >= 120;
    let width = if wide {
        area.width.min(150)
    } else {
        96.min(area.width)
    };
    let inner_width = width.saturating_sub(2);
    let (left_width, right_width) = if wide {
        let l = inner_width * 45 / 100;
        (l, inner_width - l)
    } else {
        (inner_width, inner_width)
    };
    // The table read in order: each group's heading, then its rows.
    let blocks: Vec<(&str, Option<&KeyRow>)> = groups
        .iter()
        .flat_map(|group| {
            std::iter::once((*group, None)).chain(
                KEYS.iter()
                    .filter(move |row| row.group == *group)
                    .map(move |row| (*group, Some(row))),
            )
        })
        .collect();
    let (left, right) = if wide {
        balanced_columns(&blocks, (left_width, right_width))
    } else {
        (help_column(&blocks, left_width), Vec::new())
    };
    let content = rows(&left, left_width).max(rows(&right, right_width));
    let height = content + 2;
    let r = centred(area, width, height);
    frame.render_widget(Clear, r);
    // Taller than the screen: it scrolls (↑ ↓ PgUp PgDn), and says so.
    let fits = height <= r.height;
    let max_scroll = content.saturating_sub(r.height.saturating_sub(2));
    let scroll = app.help_scroll().min(max_scroll);
    let title = if fits {
        "Keys · any key closes".to_owned()
    } else {
        format!(
            "Keys · ↑↓ PgUp PgDn scroll ({}/{}) · other keys close",
            scroll, max_scroll
        )
    };
    let block = boxed(&title, Color::Cyan);
    let inner = block.inner(r);
    frame.render_widget(block, r);
    let text = |lines: Vec<Line<'static>>| {
        Paragraph::new(lines)
            .wrap(Wrap { trim: false })
            .scroll((scroll, 0))
    };
    if wide {
        // The widths the lines were wrapped to (a layout of the
        // real rectangle may round its split a cell differently).
        let a = Rect {
            width: left_width.min(inner.width),
            ..inner
        };
        let b = Rect {
            x: a.right(),
            width: inner.width - a.width,
            ..inner
        };
        frame.render_widget(text(left), a);
        frame.render_widget(text(right), b);
    } else {
        frame.render_widget(text(left), inner);
    }
}

/// The help's blocks in one column of `width` cells: a heading before
/// each group, and again ("continued") when the column starts inside one.
fn help_column(blocks: &[(&str, Option<&KeyRow>)], width: u16) -> Vec<Line<'static>> {
    let heading = |text: String| Line::styled(text, Style::default().bold().underlined());
    let mut lines = Vec::new();
    for (k, (group, row)) in blocks.iter().enumerate() {
        match row {
            None => {
                if !lines.is_empty() {
                    lines.push(Line::raw(""));
                }
                lines.push(heading(group.to_string()));
            }
            Some(row) => {
                if k == 0 {
                    lines.push(heading(format!("{group} (continued)")));
                }
                lines.extend(key_lines(&row.keys, row.help, width));
            }
        }
    }
    lines
}

/// The blocks split in two columns where the taller column is shortest:
/// between groups, or inside one with at least two of its rows on each
/// side, so a key more or less moves the split rather than growing the
/// help by its height.
fn balanced_columns(
    blocks: &[(&str, Option<&KeyRow>)],
    (left_width, right_width): (u16, u16),
) -> (Vec<Line<'static>>, Vec<Line<'static>>) {
    // Block `k` is a key row of `group`.
    let row_of = |k: Option<usize>, group: &str| {
        k.and_then(|k| blocks.get(k))
            .is_some_and(|(g, row)| row.is_some() && *g == group)
    };
    let allowed = |k: usize| {
        let (group, row) = blocks[k];
        row.is_none()
            || (row_of(k.checked_sub(2), group)
                && row_of(k.checked_sub(1), group)
                && row_of(Some(k + 1), group))
    };
    let (left, right) = column_heights(blocks, (left_width, right_width));
    let split = (1..blocks.len())
        .filter(|&k| allowed(k))
        // A split at a heading before one inside a group.
        .min_by_key(|&k| (left[k].max(right[k]), blocks[k].1.is_some()))
        .unwrap_or(blocks.len());
    (
        help_column(&blocks[..split], left_width),
        help_column(&blocks[split..], right_width),
    )
}

/// For each split `k`, the rows `help_column` gives `blocks[..k]` at
/// `left_width` and `blocks[k..]` at `right_width`, counted once per block
/// (a heading is a line and a blank before it, but at a column's top; a
/// column that starts on a key row adds its "continued" heading) rather
/// than by building both columns for every split.
fn column_heights(
    blocks: &[(&str, Option<&KeyRow>)],
    (left_width, right_width): (u16, u16),
) -> (Vec<u16>, Vec<u16>) {
    let height = |row: Option<&KeyRow>, width: u16| {
        row.map_or(2, |r| rows(&key_lines(&r.keys, r.help, width), width))
    };
    let n = blocks.len();
    let mut left = vec![0; n + 1];
    for (k, (_, row)) in blocks.iter().enumerate() {
        // At the column's top a heading has no blank line before it.
        let top = u16::from(k == 0 && row.is_none());
        left[k + 1] = left[k] + height(*row, left_width) - top;
    }
    let mut right = vec![0; n + 1];
    let mut below = 0;
    for k in (0..n).rev() {
        let row = blocks[k].1;
        below += height(row, right_width);
        // At the column's top a heading has no blank line before it, and a
        // key row gets the "continued" heading.
        right[k] = below - u16::from(row.is_none()) + u16::from(row.is_some());
    }
    (left, right)
}

/// The keys column of the help overlay, in cells: descriptions start here.
const KEYS_COLUMN: usize = 18;

/// One key of the help overlay in a column `width` cells wide: the keys,
/// then what they do, wrapped so that every continuation line starts under
/// the description (a hanging indent), not at the left edge.
fn key_lines(keys: &str, what: &str, width: u16) -> Vec<Line<'static>> {
    let indent = KEYS_COLUMN.max(Line::raw(keys).width() + 4);
    // A blank cell at the end keeps it apart from the next column.
    let room = usize::from(width).saturating_sub(indent + 1).max(12);
    let mut lines = Vec::new();
    for (k, chunk) in wrap_words(what, room).into_iter().enumerate() {
        let lead = if k == 0 {
            key(&format!("  {keys:<w$}", w = indent - 2))
        } else {
            Span::raw(" ".repeat(indent))
        };
        lines.push(Line::from(vec![lead, Span::raw(chunk)]));
    }
    lines
}

/// `text` in lines of at most `room` cells, broken between words (a word
/// longer than a line is cut).
fn wrap_words(text: &str, room: usize) -> Vec<String> {
    let width = |s: &str| Line::raw(s).width();
    let mut lines: Vec<String> = Vec::new();
    let mut current = String::new();
    for word in text.split_whitespace() {
        let needed = width(&current) + usize::from(!current.is_empty()) + width(word);
        if needed <= room {
            if !current.is_empty() {
                current.push(' ');
            }
            current.push_str(word);
            continue;
        }
        if !current.is_empty() {
            lines.push(std::mem::take(&mut current));
        }
        // A word wider than a whole line: cut it where the line ends.
        for c in word.chars() {
            if width(&current) + width(c.encode_utf8(&mut [0; 4])) > room && !current.is_empty() {
                lines.push(std::mem::take(&mut current));
            }
            current.push(c);
        }
    }
    if !current.is_empty() || lines.is_empty() {
        lines.push(current);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_wrap_within_the_room_and_long_ones_are_cut() {
        assert_eq!(wrap_words("one two three", 7), ["one two", "three"]);
        assert_eq!(wrap_words("abcdefghij", 4), ["abcd", "efgh", "ij"]);
        assert_eq!(wrap_words("", 4), [""]);
    }

    #[test]
    fn a_wrapped_key_line_hangs_under_its_description() {
        let lines = key_lines("n  p", "next / previous item of the map", 37);
        let text: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        assert_eq!(text[0], "  n  p            next / previous");
        assert_eq!(text[1], "                  item of the map");
        assert!(lines.iter().all(|l| l.width() < 37), "{text:?}");
    }

    /// `n` one-line rows of `group`, headed.
    fn group(name: &'static str, n: usize) -> Vec<KeyRow> {
        (0..n)
            .map(|_| KeyRow {
                group: name,
                keys: "k".into(),
                help: "short",
                bindings: Vec::new(),
            })
            .collect()
    }

    fn blocks(rows: &[KeyRow]) -> Vec<(&str, Option<&KeyRow>)> {
        let mut blocks = Vec::new();
        for (k, row) in rows.iter().enumerate() {
            if k == 0 || rows[k - 1].group != row.group {
                blocks.push((row.group, None));
            }
            blocks.push((row.group, Some(row)));
        }
        blocks
    }

    #[test]
    fn help_columns_split_inside_a_long_group_without_orphans() {
        // Two short groups and one long one: split between groups, the
        // right column would hold 13 lines; two rows into the long one,
        // 11 and 11.
        let rows: Vec<KeyRow> = [group("A", 2), group("B", 2), group("C", 12)]
            .into_iter()
            .flatten()
            .collect();
        let (left, right) = balanced_columns(&blocks(&rows), (40, 40));
        let text = |lines: &[Line]| lines.iter().map(|l| l.to_string()).collect::<Vec<_>>();
        let (left, right) = (text(&left), text(&right));
        assert_eq!((left.len(), right.len()), (11, 11), "{left:?} {right:?}");
        assert_eq!(left[8], "C");
        assert_eq!(right[0], "C (continued)");
        // At least two of the split group's rows on each side.
        assert_eq!(left.len() - 9, 2);
    }

    /// The heights counted once per block are those of the columns built.
    #[test]
    fn column_heights_are_the_built_columns_rows() {
        let blocks = blocks(&KEYS);
        for widths in [(40, 60), (61, 77), (30, 30)] {
            let (left, right) = column_heights(&blocks, widths);
            for k in 0..=blocks.len() {
                assert_eq!(
                    left[k],
                    rows(&help_column(&blocks[..k], widths.0), widths.0),
                    "left of {k} at {widths:?}"
                );
                assert_eq!(
                    right[k],
                    rows(&help_column(&blocks[k..], widths.1), widths.1),
                    "right of {k} at {widths:?}"
                );
            }
        }
    }

    #[test]
    fn help_columns_split_between_groups_when_that_is_as_short() {
        let rows: Vec<KeyRow> = [group("A", 5), group("B", 5)]
            .into_iter()
            .flatten()
            .collect();
        let (left, right) = balanced_columns(&blocks(&rows), (40, 40));
        assert_eq!(left.len(), 6);
        assert_eq!(right[0].to_string(), "B");
    }
}

//! Titles (and job rows) that fit their width: a title too long for its
//! border drops whole parts, least important first, rather than lose its
//! end mid-word (at 80 × 24 the map's title ended in `step ╮`, a job's row
//! in `J 280.2 f`).

use ratatui::text::{Line, Span};

/// One part of a title: its forms, the fullest first; a part that may be
/// left out ends with an empty form. `rank` orders the giving way: the
/// highest rank first (the last such part first among equals), 0 never.
#[derive(Debug, Clone)]
pub struct Part<'a> {
    forms: Vec<Span<'a>>,
    rank: u8,
}

impl<'a> Part<'a> {
    /// A part that always stays (the pane's name).
    pub fn keep(span: Span<'a>) -> Self {
        Part {
            forms: vec![span],
            rank: 0,
        }
    }

    /// A part left out, at `rank`, when the title does not fit.
    pub fn optional(rank: u8, span: Span<'a>) -> Self {
        Part {
            forms: vec![span, Span::raw("")],
            rank,
        }
    }

    /// A part that shortens to `short` at `rank` and then stays.
    pub fn shortened(rank: u8, long: Span<'a>, short: Span<'a>) -> Self {
        Part {
            forms: vec![long, short],
            rank,
        }
    }

    /// A part that shortens to `short`, then is left out, at `rank`.
    pub fn shortened_optional(rank: u8, long: Span<'a>, short: Span<'a>) -> Self {
        Part {
            forms: vec![long, short, Span::raw("")],
            rank,
        }
    }
}

/// The parts in their order, as many and as full as fit in `width` cells:
/// while they are wider, the part of the highest rank that can give way
/// takes its next form (shorter, or none). What still does not fit loses
/// whole words from its end, marked `…`.
pub fn fit<'a>(parts: Vec<Part<'a>>, width: u16) -> Line<'a> {
    let width = usize::from(width);
    let mut form = vec![0; parts.len()];
    let wide = |form: &[usize]| -> usize {
        parts
            .iter()
            .zip(form)
            .map(|(p, &f)| p.forms[f].width())
            .sum()
    };
    while wide(&form) > width {
        let next = parts
            .iter()
            .enumerate()
            .filter(|(k, p)| p.rank > 0 && form[*k] + 1 < p.forms.len())
            .max_by_key(|(k, p)| (p.rank, *k));
        match next {
            Some((k, _)) => form[k] += 1,
            None => break,
        }
    }
    let mut spans: Vec<Span<'a>> = parts
        .into_iter()
        .zip(&form)
        .map(|(mut p, &f)| p.forms.swap_remove(f))
        .filter(|s| !s.content.is_empty())
        .collect();
    let mut used: usize = spans.iter().map(Span::width).sum();
    while used > width {
        let Some(last) = spans.pop() else { break };
        let room = width.saturating_sub(used - last.width());
        if let Some(cut) = words_within(&last.content, room) {
            spans.push(Span::styled(cut, last.style));
            break;
        }
        used -= last.width();
    }
    Line::from(spans)
}

/// The whole words of `text` that fit in `room` cells with ` …` after
/// them (and the spaces it starts and ends with), or None when not one does.
fn words_within(text: &str, room: usize) -> Option<String> {
    let lead: String = text.chars().take_while(|c| *c == ' ').collect();
    let mut out = lead.clone();
    for word in text.split_whitespace() {
        let sep = if out == lead { "" } else { " " };
        let candidate = format!("{out}{sep}{word}");
        if Span::raw(format!("{candidate} … ")).width() > room {
            break;
        }
        out = candidate;
    }
    (out != lead).then(|| format!("{out} … "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(line: &Line) -> String {
        line.spans.iter().map(|s| s.content.as_ref()).collect()
    }

    #[test]
    fn the_least_important_part_goes_first_and_whole() {
        let parts = || {
            vec![
                Part::keep(Span::raw(" Map ")),
                Part::optional(2, Span::raw("· 5.7 m/cell ")),
                Part::optional(3, Span::raw("· step 1 m ")),
                Part::shortened(
                    1,
                    Span::raw(" job 1 seed 7: feasible "),
                    Span::raw(" job 1 ✓ "),
                ),
            ]
        };
        let all = " Map · 5.7 m/cell · step 1 m  job 1 seed 7: feasible ";
        assert_eq!(text(&fit(parts(), 80)), all);
        // One cell short: the step goes, whole.
        let width = Span::raw(all).width() as u16 - 1;
        assert_eq!(
            text(&fit(parts(), width)),
            " Map · 5.7 m/cell  job 1 seed 7: feasible "
        );
        // Then the scale, then the result's short form.
        assert_eq!(text(&fit(parts(), 30)), " Map  job 1 seed 7: feasible ");
        assert_eq!(text(&fit(parts(), 20)), " Map  job 1 ✓ ");
    }

    #[test]
    fn what_still_does_not_fit_loses_whole_words() {
        let parts = vec![
            Part::keep(Span::raw(" Inspector ")),
            Part::keep(Span::raw("· Obstacle 12 'a very long name indeed' ")),
        ];
        let line = fit(parts, 36);
        assert_eq!(text(&line), " Inspector · Obstacle 12 'a very … ");
        assert!(line.width() <= 36);
    }
}

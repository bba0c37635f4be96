//! What a pipeline's result shows in the designer's jobs panel, in plain
//! words the TUI draws once for every pipeline (`tui/view/jobs.rs`): rows
//! of cells, each with a tone and, where a narrow panel may need it, a
//! shorter form.

/// How a cell reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tone {
    Plain,
    /// A heading.
    Strong,
    /// A check that holds.
    Good,
    /// The verdict when it passes.
    GoodStrong,
    /// A check that fails.
    Bad,
    /// The verdict when it fails.
    BadStrong,
    /// A caution, or no verdict.
    Warn,
}

/// One run of text in a row.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    pub text: String,
    /// A shorter form for a panel too narrow for the row.
    pub short: Option<String>,
    pub tone: Tone,
}

impl Cell {
    pub fn new(text: impl Into<String>, tone: Tone) -> Cell {
        Cell {
            text: text.into(),
            short: None,
            tone,
        }
    }

    pub fn plain(text: impl Into<String>) -> Cell {
        Cell::new(text, Tone::Plain)
    }

    /// A plain cell that shortens to `short` on a narrow panel.
    pub fn shortened(text: impl Into<String>, short: impl Into<String>) -> Cell {
        Cell {
            short: Some(short.into()),
            ..Cell::plain(text)
        }
    }
}

/// One line of the table.
pub type Row = Vec<Cell>;

/// A row of one cell.
pub fn row(text: impl Into<String>, tone: Tone) -> Row {
    vec![Cell::new(text, tone)]
}

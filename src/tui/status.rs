//! The status line: what the last action did, or why it could not. Every
//! component reports through one [`StatusLine`] the app lends it, so a
//! handler says what happened where it happens and the rules (an edit moves
//! on from an error) live in one place.

/// The status line's message.
#[derive(Debug, Clone, PartialEq)]
pub struct Status {
    pub text: String,
    pub error: bool,
}

/// The message on the status line, if any.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StatusLine {
    message: Option<Status>,
}

impl StatusLine {
    pub fn get(&self) -> Option<&Status> {
        self.message.as_ref()
    }

    pub fn set(&mut self, text: impl Into<String>, error: bool) {
        self.message = Some(Status {
            text: text.into(),
            error,
        });
    }

    /// A plain message.
    pub fn say(&mut self, text: impl Into<String>) {
        self.set(text, false);
    }

    /// An error message.
    pub fn error(&mut self, text: impl Into<String>) {
        self.set(text, true);
    }

    /// An error message is about what was; a change moves on from it.
    pub fn clear_error(&mut self) {
        if self.message.as_ref().is_some_and(|s| s.error) {
            self.message = None;
        }
    }

    /// Puts `text` before the message, unless that is an error ("saved … ·
    /// opened …").
    pub fn prefix(&mut self, text: &str) {
        if let Some(s) = self.message.as_mut().filter(|s| !s.error) {
            s.text = format!("{text} · {}", s.text);
        }
    }
}

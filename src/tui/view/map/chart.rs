//! A pipeline's chart (`pipelines::chart`) on the map's canvas: each ink
//! in its colour, lines thinned to what the screen shows.

use ratatui::style::{Color, Style};
use ratatui::text::Span;
use ratatui::widgets::canvas::Context;

use super::{Polyline, Ring, decimate, uav_color};
use crate::pipelines::chart::{Chart, Ink};

/// The colour the map gives an ink.
pub(super) fn color(ink: Ink) -> Color {
    match ink {
        Ink::Vehicle(i) => uav_color(i),
        Ink::Faded => Color::DarkGray,
        Ink::Grey => Color::Gray,
        Ink::Plain => Color::White,
        Ink::Zone => Color::LightCyan,
        Ink::Pass => Color::LightMagenta,
        Ink::Fault => Color::Red,
    }
}

/// A canvas a pipeline charts on.
pub(super) struct OnCanvas<'c, 'a> {
    pub ctx: &'c mut Context<'a>,
    /// Points of a line closer than this (metres along the axes) are one.
    pub step: f64,
    /// Metres per braille dot horizontally (how finely rings are drawn).
    pub dot: f64,
}

impl Chart for OnCanvas<'_, '_> {
    fn line(&mut self, points: Vec<[f64; 2]>, ink: Ink) {
        let points = decimate(points.into_iter().map(|[x, y]| (x, y)), self.step);
        self.ctx.draw(&Polyline {
            points: &points,
            color: color(ink),
        });
    }

    fn ring(&mut self, [x, y]: [f64; 2], radius: f64, ink: Ink) {
        self.ctx.draw(&Ring {
            x,
            y,
            radius,
            color: color(ink),
            dot: self.dot,
        });
    }

    fn mark(&mut self, [x, y]: [f64; 2], text: String, ink: Ink) {
        let style = Style::default().fg(color(ink));
        let style = if ink == Ink::Plain {
            style
        } else {
            style.bold()
        };
        self.ctx.print(x, y, Span::styled(text, style));
    }

    fn layer(&mut self) {
        self.ctx.layer();
    }
}

//! What a section is: a [`SectionKind`] (its key, its place in the outline, the tables,
//! figures and equations it numbers, its view built from the study, its record in `data.json`)
//! and the [`SectionView`] it builds (its contents entry, its template, its fields in
//! `view.json`), from a [`Context`]. The list of the report's sections is
//! [`super::registry::SECTIONS`].

use std::any::Any;
use std::fmt::Debug;

use super::equations::Equations;
use super::labels::{Label, Numbers};
use super::math::Math;
use super::{RenderError, ReportInput};
use crate::study::Study;

/// What every section is built from.
pub struct Context<'a> {
    /// The study and how the page was made.
    pub input: &'a ReportInput<'a>,
    /// The number of every table, figure and equation.
    pub numbers: &'a Numbers,
    /// The LaTeX → MathML converter.
    pub math: &'a Math,
    /// The statistics the filter assumes differently from the truth, in words.
    pub differences: &'a [String],
}

impl Context<'_> {
    /// The study.
    pub fn study(&self) -> &Study {
        self.input.study
    }
}

/// Where a section sits in the outline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// A top-level section, in the contents.
    Top,
    /// A subsection of the results (placed by the results' template).
    Results,
}

/// A section's record in `data.json`: any serializable value, written indented or compact.
pub trait JsonRecord {
    /// The record as JSON: indented by two spaces when `pretty` (as `serde_json` writes it).
    fn to_json(&self, pretty: bool) -> String;
}

impl<T: serde::Serialize> JsonRecord for T {
    fn to_json(&self, pretty: bool) -> String {
        if pretty {
            serde_json::to_string_pretty(self)
        } else {
            serde_json::to_string(self)
        }
        .expect("a record of finite numbers and text serializes")
    }
}

/// A section's data.json record: its key and its value.
pub type Record<'a> = (&'static str, Box<dyn JsonRecord + 'a>);

/// What [`SectionKind::build`] hands back: `None` when the study does not hold the section's
/// value, else its view or the error of drawing it.
pub type Built = Option<Result<Box<dyn SectionView>, RenderError>>;

/// A kind of section of the report.
pub trait SectionKind: Sync {
    /// Its stable name: `view.json`'s `"section"` and what an outline compares.
    fn key(&self) -> &'static str;

    /// Where it sits.
    fn place(&self) -> Place {
        Place::Top
    }

    /// The instances the report of `input` shows: none when the study does not hold the
    /// section's value, `[0]` for a section shown once, one per case for a case. The number
    /// tells [`Self::labels`] and [`Self::build`] which instance.
    fn instances(&self, input: &ReportInput) -> Vec<usize> {
        let _ = input;
        vec![0]
    }

    /// What `instance` numbers (tables, figures, equations), in the order its template shows
    /// them.
    fn labels(&self, instance: usize) -> Vec<Label> {
        let _ = instance;
        Vec::new()
    }

    /// The view of `instance`, every number of the outline known; `None` when the study does
    /// not hold the section's value.
    ///
    /// # Errors
    /// [`RenderError`] when a figure cannot be drawn.
    fn build(&self, ctx: &Context, instance: usize) -> Built;

    /// Its record in `data.json`, when it has one and the study holds its value.
    fn record<'a>(&self, input: &ReportInput<'a>) -> Option<Record<'a>> {
        let _ = input;
        None
    }
}

/// The view of one section: text ready for its template.
pub trait SectionView: Any + Debug + Send + Sync {
    /// The element id of the section (its contents entry links to it).
    fn anchor(&self) -> String;

    /// The section's heading (its contents entry).
    fn title(&self) -> String;

    /// The section as HTML, with the display equations `eq` and its subsections rendered.
    ///
    /// # Errors
    /// [`askama::Error`] when the template cannot be filled.
    fn html(&self, eq: &Equations, children_html: &[String]) -> Result<String, askama::Error>;

    /// Its fields as indented JSON (an object), as `view.json` shows them.
    fn fields_json(&self) -> String;

    /// Whether its template places its subsections itself (otherwise they follow it).
    fn places_children(&self) -> bool {
        false
    }

    /// The view as [`Any`], to read a section's own view back ([`super::page::SectionNode::get`]).
    fn as_any(&self) -> &dyn Any;
}

/// Implements [`SectionView`] for a view struct `$view` whose template struct `$html` takes the
/// view as field `$field` (and, after `eq`, the display equations; after `children`, the
/// subsections' HTML).
#[macro_export]
#[doc(hidden)]
macro_rules! section_view {
    ($view:ty, $html:ident { $field:ident $(, $extra:ident)* }, anchor: $anchor:expr, title: $title:expr $(, places_children: $places:expr)?) => {
        impl $crate::report::kind::SectionView for $view {
            fn anchor(&self) -> String {
                let f: fn(&$view) -> String = $anchor;
                f(self)
            }
            fn title(&self) -> String {
                let f: fn(&$view) -> String = $title;
                f(self)
            }
            #[allow(unused_variables)]
            fn html(
                &self,
                eq: &$crate::report::equations::Equations,
                children_html: &[String],
            ) -> Result<String, askama::Error> {
                use askama::Template as _;
                $crate::section_view!(@fields $html, self, eq, children_html, $field $(, $extra)*)
                    .render()
            }
            fn fields_json(&self) -> String {
                serde_json::to_string_pretty(self).expect("a view is plain text")
            }
            $(fn places_children(&self) -> bool {
                $places
            })?
            fn as_any(&self) -> &dyn std::any::Any {
                self
            }
        }
    };
    (@fields $html:ident, $s:ident, $eq:ident, $ch:ident, $field:ident) => {
        $html { $field: $s }
    };
    (@fields $html:ident, $s:ident, $eq:ident, $ch:ident, $field:ident, eq) => {
        $html { $field: $s, eq: $eq }
    };
    (@fields $html:ident, $s:ident, $eq:ident, $ch:ident, $field:ident, children) => {
        $html { $field: $s, children_html: $ch }
    };
}

//! The report's outline: which sections the page shows, in which order, and what each one holds.
//! Table, figure and equation numbers and the table of contents are derived from it, so that a
//! section moved in the outline takes its numbers and its entry in the contents along.
//!
//! Numbers are handed out like labels in a typeset document: a first pass walks the outline in
//! reading order and numbers every table, figure and equation each section declares; the
//! sections are then built with every number known, so a section may cite one that a later
//! section holds.

use std::collections::HashMap;

use super::ReportInput;
use super::kind::{Place, SectionKind};
pub use super::labels::{CheckFigure, Equation, Figure, Label, Numbers, Table};

/// The key of the results section, under which [`Place::Results`] sections sit.
pub const RESULTS: &str = "results";

/// A section of the outline: a kind of section from the registry and which instance of it
/// (the case's index for a case; 0 for a section shown once).
#[derive(Clone, Copy)]
pub struct Section {
    /// The kind.
    pub kind: &'static dyn SectionKind,
    /// The instance.
    pub instance: usize,
}

impl Section {
    /// Instance `instance` of `kind`.
    pub fn new(kind: &'static dyn SectionKind, instance: usize) -> Self {
        Section { kind, instance }
    }

    /// The kind's key ("drift", "case", …).
    pub fn key(self) -> &'static str {
        self.kind.key()
    }

    /// What the section numbers, in the order its template shows them.
    pub fn labels(self) -> Vec<Label> {
        self.kind.labels(self.instance)
    }
}

impl PartialEq for Section {
    fn eq(&self, other: &Self) -> bool {
        self.key() == other.key() && self.instance == other.instance
    }
}

impl Eq for Section {}

impl std::fmt::Debug for Section {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}[{}]", self.key(), self.instance)
    }
}

/// A section and the sections nested in it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Node {
    /// The section.
    pub section: Section,
    /// Its subsections, in order; they follow everything the section itself shows.
    pub children: Vec<Section>,
}

impl Node {
    /// A section without subsections.
    pub fn leaf(section: Section) -> Self {
        Node {
            section,
            children: Vec::new(),
        }
    }
}

/// The sections of the page, in reading order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outline {
    /// The top-level sections.
    pub nodes: Vec<Node>,
}

impl Outline {
    /// The outline of the report of `input` with the sections `kinds`, in their order: every
    /// instance each kind shows for the study, subsections of the results under the results.
    pub fn of(input: &ReportInput, kinds: &[&'static dyn SectionKind]) -> Self {
        let mut nodes: Vec<Node> = Vec::new();
        for &kind in kinds {
            for instance in kind.instances(input) {
                let section = Section::new(kind, instance);
                match kind.place() {
                    Place::Top => nodes.push(Node::leaf(section)),
                    Place::Results => {
                        match nodes.iter_mut().rev().find(|n| n.section.key() == RESULTS) {
                            Some(results) => results.children.push(section),
                            None => nodes.push(Node::leaf(section)),
                        }
                    }
                }
            }
        }
        Outline { nodes }
    }

    /// Every section in reading order, subsections after their section.
    pub fn sections(&self) -> impl Iterator<Item = Section> + '_ {
        self.nodes
            .iter()
            .flat_map(|n| std::iter::once(n.section).chain(n.children.iter().copied()))
    }

    /// Numbers every table, figure and equation in reading order, each kind from 1.
    pub fn numbers(&self) -> Numbers {
        let mut next = [0usize; 3];
        let mut map = HashMap::new();
        for label in self.sections().flat_map(Section::labels) {
            let kind = match label {
                Label::Table(_) => 0,
                Label::Figure(_) => 1,
                Label::Equation(_) => 2,
            };
            next[kind] += 1;
            map.insert(label, next[kind]);
        }
        Numbers::from_map(map)
    }
}

//! The one list of the report's sections, [`SECTIONS`], in reading order.
//!
//! A new section is one file (its [`SectionKind`], its view struct with its [`SectionView`]
//! through [`crate::section_view!`], its template struct), one template under
//! `templates/sections/`, and one line here (and its `pub mod` in `report/mod.rs`). An optional
//! section is present when the study holds its value: its [`SectionKind::instances`] is empty
//! otherwise and its [`SectionKind::build`] returns `None`; nothing else has to agree with it.

use super::kind::SectionKind;
#[cfg(doc)]
use super::kind::SectionView;
use super::{drift, ins, noise, real_drive, real_drive_3d, standard, static_noise};

/// The sections of the report, in reading order (subsections of the results after the results).
pub const SECTIONS: &[&dyn SectionKind] = &[
    &standard::Abstract,
    &standard::Introduction,
    &standard::Problem,
    &standard::Theory,
    &standard::Results,
    &standard::Case,
    &standard::Performance,
    &standard::Sensitivity,
    &static_noise::StaticNoise,
    &drift::Drift,
    &noise::Noise,
    &real_drive::RealDrive,
    &ins::Ins,
    &real_drive_3d::RealDrive3dSection,
    &standard::Conclusions,
    &standard::Appendix,
];

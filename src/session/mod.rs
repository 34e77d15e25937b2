//! A live session, headless: [`Session`] owns the background worker that refines one image or two (compare mode)
//! and a reference, the probe and the convergence history; the export of what it shows is here too. The viewer in
//! [`crate::app`] is a shell over it.

pub mod comparison;
mod model;
pub mod probe;
pub mod snapshot;
pub mod views;
pub mod worker;

pub use model::{Notify, ProbeOptions, Session, Update, series_label};

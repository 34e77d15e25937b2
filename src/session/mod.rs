//! A live session, headless: the background worker that refines one image or two (compare mode) and a
//! reference, and the export of what it shows. The viewer in [`crate::app`] is a shell over it.

pub mod comparison;
pub mod probe;
pub mod snapshot;
pub mod views;
pub mod worker;

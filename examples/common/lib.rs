//! The shared code of the crate's examples, compiled once as a crate of its own (`brdf-examples`, not
//! published) rather than once per example: each `examples/<name>.rs` is a thin main over a module of
//! `common`, and the gallery runs them all.

#[path = "mod.rs"]
pub mod common;

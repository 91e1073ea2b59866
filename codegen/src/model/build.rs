//! Building a model (placeholder).
#[derive(Debug)]
pub struct ModelError;
#[derive(Debug, Default)]
pub struct ModelOptions;
#[derive(Debug, Default)]
pub enum SymbolicParams { #[default] None }

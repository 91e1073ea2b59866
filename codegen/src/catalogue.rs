//! The catalogue of quantities: what eomgen derives, generates and evaluates, each under one
//! name, its generated method's name (`mass_matrix`, `inverse_dynamics`).
//!
//! The quantities people write with symbols have a [`Notation`] ([`NOTATIONS`]): the text and
//! LaTeX symbols `eomgen show` prints, and aliases every command accepts in place of the name
//! (`M` for `mass_matrix`, `tau` for `inverse_dynamics`). [`Builder::quantities`],
//! [`Derived::evaluate`], the reports and the command line read names through [`canonical`].
//! For one robot, every quantity with its inputs and shape is [`Derived::quantity_names`].
//!
//! ```
//! use eomgen::catalogue::{canonical, notation};
//! assert_eq!(canonical("tau"), "inverse_dynamics");
//! assert_eq!(canonical("mass_matrix"), "mass_matrix");
//! assert_eq!(notation("M").unwrap().title, "Mass matrix M(q)");
//! ```
//!
//! [`Builder::quantities`]: crate::Builder::quantities
//! [`Derived::evaluate`]: crate::Derived::evaluate
//! [`Derived::quantity_names`]: crate::Derived::quantity_names

pub use crate::dynamics::catalogue::{canonical, notation, Layout, Notation, NOTATIONS};
pub use crate::dynamics::{Input, Shape};

//! The constants that name the columns of the identification functions: `BODY_NAMES`,
//! `PARAMETER_NAMES` and `BASE_PARAMETER_NAMES`.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::dynamics::{identification, Derivation, Quantity};

/// The three constants, when any identification function is generated.
pub(super) fn constants(d: &Derivation, quantities: &[Quantity]) -> TokenStream {
    let Some(id) = &d.identification else {
        return TokenStream::new();
    };
    let generated = quantities.iter().any(|q| {
        matches!(
            q.name,
            "regressor" | "parameters" | "base_regressor" | "base_parameters"
        )
    });
    if !generated {
        return TokenStream::new();
    }
    let strings = |v: &[String]| -> (Literal, Vec<Literal>) {
        (
            Literal::usize_unsuffixed(v.len()),
            v.iter().map(|s| Literal::string(s)).collect(),
        )
    };
    let (parameters, base) = identification::names(id);
    let (nb, bodies) = strings(&id.body_names);
    let (np, parameters) = strings(&parameters);
    let (npb, base) = strings(&base);
    quote! {
        /// The URDF name of each moving body (the child link of joint `i`, fixed children
        /// merged), in joint order: the bodies of `regressor`'s column blocks.
        pub const BODY_NAMES: [&'static str; #nb] = [#(#bodies),*];
        /// The name of each standard parameter, in `regressor` and `parameters` order:
        /// `M_body` (mass), `MX_body`, `MY_body`, `MZ_body` (first moment m c), `XX_body`,
        /// `XY_body`, `YY_body`, `XZ_body`, `YZ_body`, `ZZ_body` (inertia about the body frame's
        /// origin), then `IA_joint` (rotor inertia), `FV_joint` and `FS_joint` (viscous and
        /// Coulomb friction) when generated.
        pub const PARAMETER_NAMES: [&'static str; #np] = [#(#parameters),*];
        /// The name of each base parameter, in `base_regressor` and `base_parameters` order:
        /// the standard parameter whose column it keeps, with `R` after its head when others
        /// are grouped into it (formulas in `base_parameters`' documentation).
        pub const BASE_PARAMETER_NAMES: [&'static str; #npb] = [#(#base),*];
    }
}

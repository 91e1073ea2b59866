//! The emitter's methods for the MPC kit's run-time kernels: link frames' motion
//! (`eomgen_runtime::frame`) and the configuration manifold (`eomgen_runtime::manifold`).

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::{usize_lit, Emitter};
use crate::dynamics::{Evaluation, FrameMotion, Manifold, Quantity};
use crate::model::{Joint, JointKind, Limits, Model};

impl Emitter<'_> {
    /// `link_velocity`, `link_acceleration` or `link_jacobian_time_variation`: the link's chain
    /// from `link_chain` (`link_chain_fn`), walked by the runtime. With mimic joints the
    /// coordinates' rates are first spread over the joint tree's columns (`COUPLING`), and a
    /// Jacobian's columns summed back (`J G`).
    pub(super) fn frame_motion_fn(&mut self, q: &Quantity, motion: FrameMotion) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (link_ty, n, nq) = (&self.link_ty, &self.n, &self.nq);
        let coupled = self.model.is_coupled();
        let nj = usize_lit(self.model.nv());
        let spread = |x: TokenStream| {
            if coupled {
                quote!(let #x: [T; #nj] = ::eomgen_runtime::frame::tree_rates(#x, &Self::COUPLING); let #x = &#x;)
            } else {
                TokenStream::new()
            }
        };
        let (qd_rates, qdd_rates) = (spread(quote!(qd)), spread(quote!(qdd)));
        let chain = quote!(&self.link_chain(link, q));
        match motion {
            FrameMotion::Velocity => quote! {
                #docs
                pub fn link_velocity(&self, link: #link_ty, q: &[T; #nq], qd: &[T; #n]) -> [T; 6] {
                    #qd_rates
                    ::eomgen_runtime::frame::velocity(#chain, qd)
                }
            },
            FrameMotion::Acceleration => quote! {
                #docs
                pub fn link_acceleration(&self, link: #link_ty, q: &[T; #nq], qd: &[T; #n], qdd: &[T; #n]) -> [T; 6] {
                    #qd_rates
                    #qdd_rates
                    ::eomgen_runtime::frame::acceleration(#chain, qd, qdd)
                }
            },
            FrameMotion::JacobianTimeVariation => {
                let body = if coupled {
                    quote! {
                        let joints: [[T; #nj]; 6] = ::eomgen_runtime::frame::jacobian_time_variation(#chain, qd);
                        ::eomgen_runtime::tree::couple_columns(&joints, &Self::COUPLING)
                    }
                } else {
                    quote!(::eomgen_runtime::frame::jacobian_time_variation(#chain, qd))
                };
                quote! {
                    #docs
                    pub fn link_jacobian_time_variation(&self, link: #link_ty, q: &[T; #nq], qd: &[T; #n]) -> [[T; #n]; 6] {
                        #qd_rates
                        #body
                    }
                }
            }
        }
    }

    /// The private `link_chain` that `link_velocity`, `link_acceleration` and
    /// `link_jacobian_time_variation` walk (`eomgen_runtime::frame::Chain`): the link's bodies
    /// and placement from `link_frame`, `TREE_JOINTS` and the joints' transforms at `q`. Nothing
    /// without those methods (rustc's `dead_code` warning).
    pub(super) fn link_chain_fn(&self) -> TokenStream {
        let motion = |q: &Quantity| matches!(q.eval, Evaluation::FrameMotion(_));
        if !self.quantities.iter().any(motion) {
            return TokenStream::new();
        }
        let (link_ty, nq, floating) = (&self.link_ty, &self.nq, self.floating);
        quote! {
            /// The chain from the root to a link's frame that `link_velocity`, `link_acceleration`
            /// and `link_jacobian_time_variation` walk, its joints' transforms at `q`.
            #[inline]
            fn link_chain<'a>(&'a self, link: #link_ty, q: &'a [T; #nq]) -> ::eomgen_runtime::frame::Chain<'static, T, impl Fn(usize) -> ::eomgen_runtime::Pose<T> + 'a> {
                let (path, placement) = Self::link_frame(link);
                ::eomgen_runtime::frame::Chain { path, joints: &Self::TREE_JOINTS, floating: #floating, transform: move |j| self.joint_transform(j, q), placement }
            }
        }
    }

    /// `difference`, `integrate_jacobians` or `difference_jacobians` (with its `_into` form,
    /// which writes the Jacobians' diagonal blocks into the caller's matrices) from the
    /// runtime's kernels: a floating base's, floating joints' below the root (`_blocks`), or a
    /// vector space's.
    pub(super) fn manifold_fn(&mut self, q: &Quantity, which: Manifold) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (n, nq) = (&self.n, &self.nq);
        let jacobians = quote!(([[T; #n]; #n], [[T; #n]; #n]));
        let (body, into) = self.manifold_bodies(which);
        let into_doc = |name: &str| {
            super::doc(&[
                format!("`{name}` written into `a` and `b`, their diagonal blocks only (a free flyer's"),
                "6 x 6 blocks and each other coordinate's entry), as Pinocchio's `dIntegrate` and".into(),
                "`dDifference` write each joint's block of the matrix they are given. The entries".into(),
                "off those blocks are zero in the Jacobians and are left as they are: `a` and `b`".into(),
                "must hold zeros there (zeroed once, or written by an earlier call). The values are".into(),
                format!("`{name}`'s to the bit, without writing its `2 NV^2` entries."),
            ])
        };
        let mat = quote!(&mut [[T; #n]; #n]);
        match which {
            Manifold::Difference => quote! {
                #docs
                pub fn difference(&self, q0: &[T; #nq], q1: &[T; #nq]) -> [T; #n] { #body }
            },
            Manifold::IntegrateJacobians => {
                let doc = into_doc("integrate_jacobians");
                quote! {
                    #docs
                    pub fn integrate_jacobians(&self, q: &[T; #nq], v: &[T; #n]) -> #jacobians { #body }
                    #doc
                    pub fn integrate_jacobians_into(&self, q: &[T; #nq], v: &[T; #n], a: #mat, b: #mat) { #into }
                }
            }
            Manifold::DifferenceJacobians => {
                let doc = into_doc("difference_jacobians");
                quote! {
                    #docs
                    pub fn difference_jacobians(&self, q0: &[T; #nq], q1: &[T; #nq]) -> #jacobians { #body }
                    #doc
                    pub fn difference_jacobians_into(&self, q0: &[T; #nq], q1: &[T; #nq], a: #mat, b: #mat) { #into }
                }
            }
        }
    }

    /// The bodies of `which` and of its `_into` form (none for `difference`): the runtime's
    /// floating base, floating joints below the root (`NAME_blocks`), or vector space
    /// (`vector_NAME`) kernels.
    fn manifold_bodies(&self, which: Manifold) -> (TokenStream, TokenStream) {
        let m = quote!(::eomgen_runtime::manifold);
        let free = self.free_blocks();
        let (name, args) = match which {
            Manifold::Difference => ("difference", quote!(q0, q1)),
            Manifold::IntegrateJacobians => ("integrate_jacobians", quote!(q, v)),
            Manifold::DifferenceJacobians => ("difference_jacobians", quote!(q0, q1)),
        };
        let f = |prefix: &str, suffix: &str| format_ident!("{prefix}{name}{suffix}");
        let (plain, blocks, vector) = (f("", ""), f("", "_blocks"), f("vector_", ""));
        let (body, into) = if self.floating {
            let into = f("", "_into");
            (quote!(#m::#plain(#args)), quote!(#m::#into(#args, a, b)))
        } else if !self.model.floating_joints().is_empty() {
            let into = f("", "_blocks_into");
            (
                quote!(#m::#blocks(#args, #free)),
                quote!(#m::#into(#args, #free, a, b)),
            )
        } else {
            // A vector space's Jacobians are constant: their kernels take no state.
            let into = f("vector_", "_into");
            let body = match which {
                Manifold::Difference => quote!(#m::#vector(#args)),
                _ => quote!(#m::#vector()),
            };
            (body, quote!({ let _ = (#args); #m::#into(a, b) }))
        };
        match which {
            Manifold::Difference => (body, TokenStream::new()),
            _ => (body, into),
        }
    }
}

/// `POSITION_LIMITS`, `VELOCITY_LIMITS` and `EFFORT_LIMITS`: the URDF's `<limit>` of each
/// joint coordinate (`JOINT_NAMES` order, without a floating base's six), infinite where it
/// sets none (a `continuous` joint's position, a joint without `<limit>`).
pub(super) fn limit_constants(model: &Model) -> TokenStream {
    let joints: Vec<&Joint> = model
        .coordinate_joints()
        .into_iter()
        .map(|j| &model.joints[j])
        .collect();
    let n = usize_lit(joints.len());
    let limit =
        |j: &Joint, f: fn(&Limits) -> f64| j.limits.as_ref().map(f).unwrap_or(f64::INFINITY);
    let positions = joints.iter().map(|j| {
        let (lower, upper) = match (&j.limits, j.kind) {
            (Some(l), JointKind::Revolute | JointKind::Prismatic) => (l.lower, l.upper),
            _ => (f64::NEG_INFINITY, f64::INFINITY),
        };
        let (lower, upper) = (bound(lower), bound(upper));
        quote!((#lower, #upper))
    });
    let velocities = joints.iter().map(|j| bound(limit(j, |l| l.velocity)));
    let efforts = joints.iter().map(|j| bound(limit(j, |l| l.effort)));
    let base = if model.is_floating() {
        " (the joints only: entry `i` is velocity coordinate `6 + i`)"
    } else {
        ""
    };
    let position_doc = format!(" Each joint coordinate's position limits `(lower, upper)` (rad or m) from the URDF's `<limit>`, in `JOINT_NAMES` order{base}; infinite for `continuous` joints and joints without `<limit>`.");
    let velocity_doc = format!(" Each joint coordinate's velocity limit (rad/s or m/s) from the URDF's `<limit velocity>`, in `JOINT_NAMES` order{base}; infinite without `<limit>`.");
    let effort_doc = format!(" Each joint coordinate's effort limit (N m or N) from the URDF's `<limit effort>`, in `JOINT_NAMES` order{base}; infinite without `<limit>`.");
    quote! {
        #[doc = #position_doc]
        pub const POSITION_LIMITS: [(f64, f64); #n] = [#(#positions),*];
        #[doc = #velocity_doc]
        pub const VELOCITY_LIMITS: [f64; #n] = [#(#velocities),*];
        #[doc = #effort_doc]
        pub const EFFORT_LIMITS: [f64; #n] = [#(#efforts),*];
    }
}

/// An `f64` constant, infinities by name.
fn bound(x: f64) -> TokenStream {
    if x == f64::INFINITY {
        quote!(f64::INFINITY)
    } else if x == f64::NEG_INFINITY {
        quote!(f64::NEG_INFINITY)
    } else {
        super::links::f64_literal(x)
    }
}

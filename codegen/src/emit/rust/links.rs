//! Link kinematics: `link_pose` and `link_jacobian` as loops over per-joint transforms
//! (straight-line code each) along a link's chain, with the tables they walk.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::{usize_lit, Emitter};
use crate::cas::Id;
use crate::dynamics::{Derivation, Evaluation, Quantity, Shape};
use crate::emit::body::body;
use crate::emit::expr::lit;
use crate::kinematics::snap;
use crate::model::{JointKind, Transform};
use crate::spatial::snap_rotation;

impl Emitter<'_> {
    pub(super) fn link_pose_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (link_ty, nq) = (&self.link_ty, &self.nq);
        quote! {
            #docs
            pub fn link_pose(&self, link: #link_ty, q: &[T; #nq]) -> ::eomgen_runtime::Pose<T> {
                let (path, placement) = Self::link_frame(link);
                ::eomgen_runtime::tree::chain_pose(path, |j| self.joint_transform(j, q)).compose(&placement)
            }
        }
    }

    pub(super) fn link_jacobian_fn(&mut self, q: &Quantity) -> TokenStream {
        let docs = Self::quantity_doc(q, None);
        let (link_ty, n, nq) = (&self.link_ty, &self.n, &self.nq);
        let kernel = if self.floating {
            quote!(::eomgen_runtime::free_flyer::chain_jacobian)
        } else {
            quote!(::eomgen_runtime::tree::chain_jacobian)
        };
        if !self.model.floating_joints().is_empty() {
            // Joints of several columns: each joint's first column from a table.
            let columns = self.model.v_offsets().into_iter().map(usize_lit);
            let nj = usize_lit(self.model.joints.len());
            return quote! {
                #docs
                pub fn link_jacobian(&self, link: #link_ty, q: &[T; #nq]) -> [[T; #n]; 6] {
                    const COLUMNS: [usize; #nj] = [#(#columns),*];
                    let (path, placement) = Self::link_frame(link);
                    ::eomgen_runtime::tree::chain_jacobian_columns(path, &Self::TREE_JOINTS, &COLUMNS, |j| self.joint_transform(j, q), &placement)
                }
            };
        }
        if self.model.is_coupled() {
            // Columns per joint (after a floating base's six), then summed into the
            // coordinates' (`J G`).
            let nj = usize_lit(self.model.nv());
            return quote! {
                #docs
                pub fn link_jacobian(&self, link: #link_ty, q: &[T; #nq]) -> [[T; #n]; 6] {
                    let (path, placement) = Self::link_frame(link);
                    let joints: [[T; #nj]; 6] = #kernel(path, &Self::TREE_JOINTS, |j| self.joint_transform(j, q), &placement);
                    ::eomgen_runtime::tree::couple_columns(&joints, &Self::COUPLING)
                }
            };
        }
        quote! {
            #docs
            pub fn link_jacobian(&self, link: #link_ty, q: &[T; #nq]) -> [[T; #n]; 6] {
                let (path, placement) = Self::link_frame(link);
                #kernel(path, &Self::TREE_JOINTS, |j| self.joint_transform(j, q), &placement)
            }
        }
    }

    /// What link kinematics walks: each joint's transform as straight-line code, the joint
    /// axes, per link its chain from the root and its placement in its body, and the frames'
    /// motion's `link_chain`.
    pub(super) fn frame_support(&mut self, d: &Derivation) -> TokenStream {
        let nq = &self.nq;
        let arms: Vec<TokenStream> = d
            .joint_transforms
            .iter()
            .enumerate()
            .map(|(j, t)| {
                let mut outs: Vec<Id> = t.translation.to_vec();
                outs.extend(t.rotation.iter().flatten());
                let b = body(self.graph, &self.cx, &outs, Shape::Vector(12), None).code;
                let j = usize_lit(j);
                quote!(#j => { let o = { #b }; ::eomgen_runtime::Pose { translation: [o[0], o[1], o[2]], rotation: [[o[3], o[4], o[5]], [o[6], o[7], o[8]], [o[9], o[10], o[11]]] } })
            })
            .collect();
        let link_arms = self.link_frame_arms();
        let link_ty = &self.link_ty;
        let tables = self.jacobian_tables();
        let chain = self.link_chain_fn();
        quote! {
            #tables

            /// The pose of body `j` in its parent body's frame (a floating base is body 0), inlined
            /// into the walks along a chain: returned through memory, its 12 numbers were stored
            /// one by one and read back as wide vectors, which cannot be forwarded (a third of the
            /// panda's `link_velocity`).
            #[inline]
            fn joint_transform(&self, j: usize, q: &[T; #nq]) -> ::eomgen_runtime::Pose<T> {
                match j {
                    #(#arms)*
                    _ => ::eomgen_runtime::Pose::identity(),
                }
            }

            /// A link's chain of joints from the root and its placement in the last body.
            fn link_frame(link: #link_ty) -> (&'static [usize], ::eomgen_runtime::Pose<T>) {
                match link { #(#link_arms)* }
            }

            #chain
        }
    }

    /// `TREE_JOINTS` (each joint's axis and motion) and, with coupled joints, `COUPLING`: the
    /// tables `link_jacobian` and the frames' motion walk.
    fn jacobian_tables(&self) -> TokenStream {
        let nj = usize_lit(self.model.joints.len());
        let joints = self.model.joints.iter().map(|j| {
            let axis = j.axis.map(snap);
            let [x, y, z] = [0, 1, 2].map(|k| f64_literal(axis[k]));
            let motion = match j.kind {
                JointKind::Floating => quote!(Free),
                JointKind::Revolute | JointKind::Continuous => quote!(Rotation),
                JointKind::Prismatic => quote!(Translation),
            };
            quote!(::eomgen_runtime::tree::TreeJoint { axis: [#x, #y, #z], motion: ::eomgen_runtime::tree::Motion::#motion })
        });
        // The joint axes and the coupling are read by `link_jacobian` and the frames' motion
        // alone: without them, a `link_pose` selection would carry unused constants (rustc's
        // `dead_code` warning).
        let jacobian = self.quantities.iter().any(|q| {
            matches!(
                q.eval,
                Evaluation::LinkJacobian | Evaluation::FrameMotion(_)
            )
        });
        let coupling = if jacobian && self.model.is_coupled() {
            let v0 = self.model.base_nv();
            let base = (0..v0).map(|i| (i, 1.0));
            let joints = self
                .model
                .coupling
                .iter()
                .map(|c| (v0 + c.coordinate, c.multiplier));
            let entries = base.chain(joints).map(|(i, k)| {
                let (i, k) = (usize_lit(i), f64_literal(k));
                quote!((#i, #k))
            });
            let nv = usize_lit(self.model.nv());
            quote! {
                /// Per velocity column of the joint tree (a floating base's six, then one per
                /// joint), the coordinate it follows and its multiplier (its rate is the
                /// multiplier times the coordinate's).
                const COUPLING: [(usize, f64); #nv] = [#(#entries),*];
            }
        } else {
            TokenStream::new()
        };
        let tree_joints = if jacobian {
            quote! {
                /// Each joint's axis (in the frame of the body it moves) and motion.
                const TREE_JOINTS: [::eomgen_runtime::tree::TreeJoint; #nj] = [#(#joints),*];
            }
        } else {
            TokenStream::new()
        };
        quote! {
            #tree_joints
            #coupling
        }
    }

    /// Each link's arm of `link_frame`: its chain of bodies from the root and its placement.
    fn link_frame_arms(&self) -> Vec<TokenStream> {
        let link_ty = &self.link_ty;
        self.model
            .frames
            .iter()
            .zip(self.link_variants())
            .map(|(f, v)| {
                // Bodies from the root; a floating base is body 0, before the joints' bodies.
                let shift = usize::from(self.floating);
                let base = self.floating.then_some(0);
                let path: Vec<Literal> = match f.body {
                    Some(b) => base
                        .into_iter()
                        .chain(self.model.path_to_root(b).into_iter().map(|j| j + shift))
                        .map(usize_lit)
                        .collect(),
                    None => base.into_iter().map(usize_lit).collect(),
                };
                let pose = constant_pose(&f.placement);
                quote!(#link_ty::#v => (&[#(#path),*], #pose),)
            })
            .collect()
    }
}

/// A constant pose as `Pose { .. }` with `T::from_f64` literals (rotation entries snapped).
fn constant_pose(t: &Transform) -> TokenStream {
    let tr = (0..3).map(|k| lit(t.translation[k]));
    let rotation = snap_rotation(&t.rotation);
    let rows = (0..3).map(|r| {
        let row = (0..3).map(|c| lit(rotation[(r, c)]));
        quote!([#(#row),*])
    });
    quote!(::eomgen_runtime::Pose { translation: [#(#tr),*], rotation: [#(#rows),*] })
}

/// An `f64` literal, negative ones as a negation.
pub(super) fn f64_literal(v: f64) -> TokenStream {
    let l = Literal::f64_unsuffixed(v.abs());
    if v < 0.0 {
        quote!(-#l)
    } else {
        quote!(#l)
    }
}

//! The library's errors print the same in `Debug` as in `Display`.
//!
//! A build script ends in `.compile().unwrap()`, and `unwrap` prints the error's `Debug` form:
//! this makes it the readable one-line message (`robot.urdf: the robot has no links`) instead of
//! the variant's fields (`Model(NoLinks { file: "robot.urdf" })`). Match on the variants to
//! inspect the fields.

/// Implements `Debug` for each type by delegating to its `Display`.
macro_rules! debug_as_display {
    ($($ty:ty),+) => {$(
        impl ::core::fmt::Debug for $ty {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                ::core::fmt::Display::fmt(self, f)
            }
        }
    )+};
}

debug_as_display!(crate::Error, crate::ModelError);

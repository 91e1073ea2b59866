//! A synthetic serial chain URDF of any length, for scaling measurements and tests.
//!
//! Include it with `#[path = "support/chain.rs"] mod chain;` (from `tests/`) or
//! `#[path = "../tests/support/chain.rs"] mod chain;` (from `examples/`).
//!
//! The chain is deliberately not a textbook arm with zeros everywhere: joint axes alternate
//! between z and y, every joint origin is offset along all three axes, every centre of mass is off
//! the joint axis and every inertia tensor has non-zero products of inertia, so that no term
//! vanishes by accident and operation counts reflect a generic robot.

// A test that includes this module may use only part of it.
#![allow(dead_code)]

use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};

/// The URDF of a fixed-base serial chain of `n` revolute joints: links `base`, `link1` ...
/// `linkN` and joints `joint1` ... `jointN`, joint `i` moving `link<i>`.
pub fn serial_chain_urdf(n: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0"?>"#);
    let _ = writeln!(s, r#"<robot name="chain{n}">"#);
    let _ = writeln!(s, r#"  <link name="base"/>"#);
    for i in 1..=n {
        let f = i as f64;
        // Alternating axes, like most arms (a pitch joint between two yaw joints).
        let axis = if i % 2 == 1 { "0 0 1" } else { "0 1 0" };
        // Link lengths and side offsets vary from joint to joint (sign flips every other one).
        let sign = if i % 2 == 0 { -1.0 } else { 1.0 };
        let origin = [
            0.02 + 0.005 * (i % 3) as f64,
            sign * 0.03,
            0.15 + 0.01 * (i % 4) as f64,
        ];
        let parent = if i == 1 {
            "base".to_string()
        } else {
            format!("link{}", i - 1)
        };
        // Lighter links towards the tip; the centre of mass is off the joint axis.
        let mass = 3.0 / (1.0 + 0.1 * f);
        let com = [
            0.01 * sign,
            0.005 + 0.001 * (i % 5) as f64,
            0.06 + 0.002 * f,
        ];
        // A diagonally dominant tensor: positive definite and, for every length, within the
        // triangle inequality (each moment grows slower than the sum of the other two).
        let (ixx, iyy, izz) = (0.010 + 0.0004 * f, 0.012 + 0.0003 * f, 0.006 + 0.0002 * f);
        let (ixy, ixz, iyz) = (0.0004 * sign, -0.0003, 0.0002 * (1 + i % 3) as f64);
        let _ = writeln!(s, r#"  <link name="link{i}">"#);
        let _ = writeln!(s, r#"    <inertial>"#);
        let _ = writeln!(
            s,
            r#"      <origin xyz="{} {} {}" rpy="0 0 0"/>"#,
            com[0], com[1], com[2]
        );
        let _ = writeln!(s, r#"      <mass value="{mass}"/>"#);
        let _ = writeln!(
            s,
            r#"      <inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/>"#
        );
        let _ = writeln!(s, r#"    </inertial>"#);
        let _ = writeln!(s, r#"  </link>"#);
        let _ = writeln!(s, r#"  <joint name="joint{i}" type="revolute">"#);
        let _ = writeln!(s, r#"    <parent link="{parent}"/>"#);
        let _ = writeln!(s, r#"    <child link="link{i}"/>"#);
        let _ = writeln!(
            s,
            r#"    <origin xyz="{} {} {}" rpy="0 0 0"/>"#,
            origin[0], origin[1], origin[2]
        );
        let _ = writeln!(s, r#"    <axis xyz="{axis}"/>"#);
        let _ = writeln!(
            s,
            r#"    <limit lower="-2.8" upper="2.8" effort="100" velocity="2"/>"#
        );
        let _ = writeln!(s, r#"  </joint>"#);
    }
    let _ = writeln!(s, "</robot>");
    s
}

/// Writes [`serial_chain_urdf`]`(n)` to `dir/chain<n>.urdf` and returns the path.
pub fn write_serial_chain(dir: &Path, n: usize) -> io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let path = dir.join(format!("chain{n}.urdf"));
    std::fs::write(&path, serial_chain_urdf(n))?;
    Ok(path)
}

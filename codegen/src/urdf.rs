//! URDF reading (placeholder).

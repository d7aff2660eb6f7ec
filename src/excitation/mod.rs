//! excitation

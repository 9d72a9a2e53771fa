//! The design-file schema (serde) and its validation.

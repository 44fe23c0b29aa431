//! The one scene-file reader: a TOML file of any family read into a [`crate::scene::Scene`].

/// The key under `[data]` of a scene file for the model's data function `name`: its
/// ASCII spelling (`ψ` is `psi`).
pub fn data_key(name: &str) -> String {
    match name {
        "ψ" => "psi".into(),
        "λ" => "lambda".into(),
        other => other.into(),
    }
}

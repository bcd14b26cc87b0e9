//! Numbers and errors as the editor's status line and panels show them.

/// The error and its causes on one line, skipping causes the message already quotes.
pub fn error_text(error: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in error.chain() {
        let text = cause.to_string();
        if !message.contains(&text) {
            if !message.is_empty() {
                message.push_str(": ");
            }
            message.push_str(&text);
        }
    }
    message
}

/// `1234567` → `1,234,567`.
pub fn thousands(value: u64) -> String {
    meshpaint_core::colors::budget::thousands_with(value, ',')
}

/// `bytes` as B / KiB / MiB / GiB / TiB with one decimal (the budget messages' format).
pub fn human_bytes(bytes: u64) -> String {
    meshpaint_core::colors::budget::bytes_text(bytes)
}

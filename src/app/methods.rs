//! `dermis methods`: the method registry, as a table or JSON.

use anyhow::Result;

use super::cli::MethodsArgs;
use crate::method::{listing, listing_text};

pub fn run(a: &MethodsArgs) -> Result<()> {
    if a.json {
        println!("{}", serde_json::to_string_pretty(&listing())?);
    } else {
        print!("{}", listing_text());
    }
    Ok(())
}

//! The run header every JSON file dermis writes carries at its top (issue 27):
//! which dermis, which command line, which device and driver, the frame's
//! size and how many frames were warmed up and measured. One type, flattened
//! into each output's schema under the same field names `report.json` has
//! always used, so every reader of reports reads old files too.
//!
//! Pure: the device part is filled by whoever opened the device
//! (`report::device_header`); a command that opens none (`dermis plan`) says
//! so with [`DeviceHeader::none`].

use serde::{Deserialize, Serialize};

/// The device a run measured on, as the driver names it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceHeader {
    pub device: String,
    pub device_type: String,
    pub driver: String,
    pub vulkan_api: String,
    /// Whether the Khronos validation layer was on (every message fails the run).
    pub validation: bool,
}

/// What [`DeviceHeader::none`] writes as the device of a run that opened none.
pub const NO_DEVICE: &str = "none";

impl DeviceHeader {
    /// The device of a command that opens none (`plan`): its figures come
    /// from the cost model and stored frames alone.
    pub fn none() -> Self {
        DeviceHeader {
            device: NO_DEVICE.into(),
            device_type: NO_DEVICE.into(),
            driver: NO_DEVICE.into(),
            vulkan_api: NO_DEVICE.into(),
            validation: false,
        }
    }
}

/// The header of one run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunHeader {
    pub dermis_version: String,
    /// The command line as given (program name and every argument).
    pub command: String,
    #[serde(flatten)]
    pub device: DeviceHeader,
    /// The frame's size in pixels (a sweep's views share it).
    pub width: u32,
    pub height: u32,
    /// Frames rendered before the measured ones, and measured (per rendered
    /// configuration of a sweep; 0 and 0 for a command that renders none).
    pub warmup_frames: usize,
    pub measured_frames: usize,
}

impl RunHeader {
    /// This build's header for `command` on `device`.
    pub fn new(
        command: &str,
        device: DeviceHeader,
        (width, height): (u32, u32),
        (warmup_frames, measured_frames): (usize, usize),
    ) -> Self {
        RunHeader {
            dermis_version: env!("CARGO_PKG_VERSION").to_string(),
            command: command.to_string(),
            device,
            width,
            height,
            warmup_frames,
            measured_frames,
        }
    }

    /// The one line a command prints above its table.
    pub fn line(&self) -> String {
        format!(
            "dermis {} | {} ({}) | {}x{} | {} warm-up + {} measured frames",
            self.dermis_version,
            self.device.device,
            self.device.driver,
            self.width,
            self.height,
            self.warmup_frames,
            self.measured_frames
        )
    }
}

/// The command line of this process, as the header records it.
pub fn command_line() -> String {
    std::env::args().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    // Flattened, the header's fields sit at the top of the JSON under the
    // names report.json has always had, and read back equal.
    #[test]
    fn the_header_flattens_under_the_report_field_names() {
        let h = RunHeader::new("dermis plan", DeviceHeader::none(), (320, 180), (0, 0));
        let v = serde_json::to_value(&h).unwrap();
        for key in [
            "dermis_version",
            "command",
            "device",
            "device_type",
            "driver",
            "vulkan_api",
            "validation",
            "width",
            "height",
            "warmup_frames",
            "measured_frames",
        ] {
            assert!(v.get(key).is_some(), "{key} missing: {v}");
        }
        assert_eq!(v["device"], NO_DEVICE);
        let back: RunHeader = serde_json::from_value(v).unwrap();
        assert_eq!(back, h);
        assert!(h.line().contains("320x180"), "{}", h.line());
    }
}

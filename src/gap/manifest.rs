//! Writing a campaign out as a test engineer keeps it: the TOML manifest with its
//! accelerometer records in CSV files beside it (the form [`Campaign::load`] reads).

use super::accel;
use super::campaign::{Campaign, FORMAT_VERSION};
use super::GapError;
use std::path::Path;

impl Campaign {
    /// The manifest TOML and the CSV files (name, text) that hold this campaign; records'
    /// samples go to `<test>_<specimen>_inc<k>_<location>.csv`.
    pub fn to_manifest(&self) -> Result<(String, Vec<(String, String)>), GapError> {
        let mut manifest = self.clone();
        let mut files = Vec::new();
        for test in &mut manifest.tests {
            for spec in &mut test.specimens {
                for rec in &mut spec.accelerometers {
                    let name = format!(
                        "{}_{}_inc{}_{}.csv",
                        test.id,
                        spec.id,
                        rec.increment,
                        rec.location.as_str()
                    );
                    files.push((name.clone(), accel::to_csv(&rec.samples)));
                    rec.samples.clear();
                    rec.csv = Some(name);
                }
            }
        }
        let text = toml::to_string(&manifest).map_err(|e| GapError::Write {
            path: "campaign.toml".into(),
            message: e.to_string(),
        })?;
        Ok((text, files))
    }

    /// Writes `<dir>/campaign.toml` and its CSV files.
    pub fn write_dir(&self, dir: &Path) -> Result<(), GapError> {
        let (text, files) = self.to_manifest()?;
        let write = |name: &str, body: &str| {
            let path = dir.join(name);
            std::fs::write(&path, body).map_err(|e| GapError::Write {
                path: path.display().to_string(),
                message: e.to_string(),
            })
        };
        std::fs::create_dir_all(dir).map_err(|e| GapError::Write {
            path: dir.display().to_string(),
            message: e.to_string(),
        })?;
        write(
            "campaign.toml",
            &format!(
                "# Test campaign, format version {FORMAT_VERSION} (railwear campaign check \
                 <file>). Units are in the key names.\n{text}"
            ),
        )?;
        for (name, body) in &files {
            write(name, body)?;
        }
        Ok(())
    }
}

//! Wall-clock helpers: times are stored as Unix milliseconds and shown as RFC 3339 UTC.

/// Now, Unix milliseconds.
pub fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_millis() as i64)
        .unwrap_or(0)
}

/// Days since 1970-01-01 -> (year, month, day) in the proleptic Gregorian calendar
/// (Howard Hinnant's civil-from-days algorithm).
fn civil_from_days(days: i64) -> (i64, i64, i64) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

/// Unix ms -> `YYYY-MM-DDTHH:MM:SS.mmmZ`.
pub fn rfc3339(ms: i64) -> String {
    let secs = ms.div_euclid(1000);
    let millis = ms.rem_euclid(1000);
    let (y, m, d) = civil_from_days(secs.div_euclid(86_400));
    let sod = secs.rem_euclid(86_400);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}.{millis:03}Z",
        sod / 3600,
        (sod / 60) % 60,
        sod % 60
    )
}

/// (year, month, day) in the proleptic Gregorian calendar -> days since 1970-01-01 (Howard
/// Hinnant's days-from-civil algorithm).
fn days_from_civil(year: i64, month: i64, day: i64) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y.rem_euclid(400);
    let mp = (month + 9) % 12;
    let doy = (153 * mp + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Days in `month` of `year` (Gregorian leap years).
pub fn days_in_month(year: i64, month: i64) -> i64 {
    match month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if (year % 4 == 0 && year % 100 != 0) || year % 400 == 0 => 29,
        2 => 28,
        _ => 0,
    }
}

/// An ISO 8601 date (`YYYY-MM-DD`, midnight UTC) or RFC 3339 date-time
/// (`YYYY-MM-DDTHH:MM:SS[.frac](Z|±HH:MM)`) as Unix milliseconds; `None` unless every field is
/// in range and the day exists in its month (2024-02-30 and 2023-02-29 do not).
pub fn parse_iso8601_ms(text: &str) -> Option<i64> {
    let b = text.as_bytes();
    let digits = |range: std::ops::Range<usize>| -> Option<i64> {
        let part = text.get(range)?;
        if part.bytes().all(|c| c.is_ascii_digit()) {
            part.parse().ok()
        } else {
            None
        }
    };
    let (year, month, day) = (digits(0..4)?, digits(5..7)?, digits(8..10)?);
    if b.get(4) != Some(&b'-') || b.get(7) != Some(&b'-') {
        return None;
    }
    if !(1..=12).contains(&month) || !(1..=days_in_month(year, month)).contains(&day) {
        return None;
    }
    let midnight_ms = days_from_civil(year, month, day) * 86_400_000;
    if b.len() == 10 {
        return Some(midnight_ms);
    }
    if !matches!(b.get(10), Some(b'T') | Some(b't') | Some(b' ')) {
        return None;
    }
    let (h, mi, sec) = (digits(11..13)?, digits(14..16)?, digits(17..19)?);
    if b.get(13) != Some(&b':') || b.get(16) != Some(&b':') || h > 23 || mi > 59 || sec > 60 {
        return None;
    }
    let mut rest = text.get(19..)?;
    let mut millis = 0;
    if let Some(frac) = rest.strip_prefix('.') {
        let n = frac.bytes().take_while(u8::is_ascii_digit).count();
        if n == 0 {
            return None;
        }
        let first3: String = frac[..n].chars().chain("000".chars()).take(3).collect();
        millis = first3.parse::<i64>().ok()?;
        rest = &frac[n..];
    }
    let offset_s = match rest {
        "Z" | "z" => 0,
        offset
            if offset.len() == 6
                && offset.is_ascii()
                && (offset.starts_with('+') || offset.starts_with('-')) =>
        {
            let o = offset.as_bytes();
            let oh = offset[1..3].parse::<i64>().ok().filter(|v| *v <= 23)?;
            let om = offset[4..6].parse::<i64>().ok().filter(|v| *v <= 59)?;
            if o[3] != b':'
                || !offset[1..3]
                    .bytes()
                    .chain(offset[4..6].bytes())
                    .all(|c| c.is_ascii_digit())
            {
                return None;
            }
            let sign = if o[0] == b'-' { -1 } else { 1 };
            sign * (oh * 3600 + om * 60)
        }
        _ => return None,
    };
    Some(midnight_ms + ((h * 3600 + mi * 60 + sec) - offset_s) * 1000 + millis)
}

/// True for an ISO 8601 date (`YYYY-MM-DD`) or RFC 3339 date-time
/// (`YYYY-MM-DDTHH:MM:SS[.frac](Z|±HH:MM)`) with in-range fields and a day that exists.
pub fn is_iso8601(text: &str) -> bool {
    parse_iso8601_ms(text).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rfc3339_known_instants() {
        assert_eq!(rfc3339(0), "1970-01-01T00:00:00.000Z");
        // 2000-02-29T12:34:56.789Z (leap day) = 951827696789 ms.
        assert_eq!(rfc3339(951_827_696_789), "2000-02-29T12:34:56.789Z");
    }

    #[test]
    fn iso8601_accepts_and_rejects() {
        assert!(is_iso8601("2024-05-01"));
        assert!(is_iso8601("2024-05-01T08:30:00Z"));
        assert!(is_iso8601("2024-05-01T08:30:00.25+02:00"));
        assert!(!is_iso8601("2024-13-01"));
        assert!(!is_iso8601("01/05/2024"));
        assert!(!is_iso8601("2024-05-01T25:00:00Z"));
        assert!(!is_iso8601("2024-05-01T08:30:00"));
        assert!(!is_iso8601(""));
    }

    #[test]
    fn calendar_days_must_exist() {
        assert!(!is_iso8601("2024-02-30"));
        assert!(!is_iso8601("2023-02-29"));
        assert!(!is_iso8601("2024-04-31T08:00:00Z"));
        assert!(is_iso8601("2024-02-29"));
        assert!(is_iso8601("2000-02-29"));
        assert!(!is_iso8601("1900-02-29"));
    }

    #[test]
    fn parsed_instants_agree_with_rfc3339() {
        for ms in [0, 951_827_696_789, 1_714_552_200_000, -86_400_000] {
            assert_eq!(parse_iso8601_ms(&rfc3339(ms)), Some(ms));
        }
        // Offsets move the instant; a date alone is midnight UTC.
        assert_eq!(
            parse_iso8601_ms("2024-05-01T10:30:00+02:00"),
            parse_iso8601_ms("2024-05-01T08:30:00Z")
        );
        assert_eq!(
            parse_iso8601_ms("2024-05-01"),
            parse_iso8601_ms("2024-05-01T00:00:00Z")
        );
        assert_eq!(
            parse_iso8601_ms("2024-05-01T08:30:00.5Z").map(|v| v % 1000),
            Some(500)
        );
    }
}

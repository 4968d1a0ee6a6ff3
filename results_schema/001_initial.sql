-- Schema version 1 of the study database. Applied in one transaction; PRAGMA user_version = 1.
-- A case is its parameter hash (case_id): one row in `cases` however many studies contain it.
CREATE TABLE studies (
  name        TEXT PRIMARY KEY,
  source_toml TEXT NOT NULL,      -- the study file as last run
  created_at  TEXT NOT NULL,
  updated_at  TEXT NOT NULL
);

CREATE TABLE cases (
  id          TEXT PRIMARY KEY,   -- case_id: hash of the fully resolved parameters
  scene       TEXT NOT NULL,
  angle_deg   REAL NOT NULL,      -- gravity.angle_deg, the paper's abscissa
  params_json TEXT NOT NULL,      -- canonical JSON, every key, defaults included
  created_at  TEXT NOT NULL
);

-- Membership of a case in a study group (a case may sit in several studies).
CREATE TABLE study_cases (
  study      TEXT NOT NULL REFERENCES studies(name),
  group_name TEXT NOT NULL,
  case_id    TEXT NOT NULL REFERENCES cases(id),
  position   INTEGER NOT NULL,    -- order in the study file's expansion
  PRIMARY KEY (study, group_name, case_id)
);

-- The keys a study sets on a case (group `set`, matrix, zip), as TOML text and, when numeric,
-- as a number for SQL filtering.
CREATE TABLE case_values (
  case_id   TEXT NOT NULL REFERENCES cases(id),
  key       TEXT NOT NULL,
  value     TEXT NOT NULL,
  value_num REAL,
  PRIMARY KEY (case_id, key)
);

CREATE TABLE attempts (
  id              INTEGER PRIMARY KEY AUTOINCREMENT,
  case_id         TEXT NOT NULL REFERENCES cases(id),
  started_at      TEXT NOT NULL,
  ended_at        TEXT,           -- NULL while running (or if the driver died)
  host            TEXT NOT NULL,
  ranks           INTEGER NOT NULL,
  exit_status     INTEGER,        -- solver exit code; NULL: abandoned or running
  error_text      TEXT,
  program_version TEXT NOT NULL
);

CREATE TABLE results (
  case_id                      TEXT PRIMARY KEY REFERENCES cases(id),
  attempt_id                   INTEGER REFERENCES attempts(id),
  mean_settling_velocity_m_s   REAL,
  settling_velocity_stderr_m_s REAL,
  average_from_s               REAL,  -- averaging window of <<w_p>>
  average_to_s                 REAL,
  wall_time_s                  REAL,
  particle_steps               INTEGER,
  validation_errors_json       TEXT,  -- the scene's measured errors (keys containing "error")
  summary_json                 TEXT NOT NULL,
  recorded_at                  TEXT NOT NULL
);

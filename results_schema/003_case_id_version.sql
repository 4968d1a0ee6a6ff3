-- Schema version 3: the identity scheme of the stored case ids. Version 2 hashes only the keys a
-- case's scene reads and leaves out the run's length and output (time.end, time.checkpoint_every,
-- output.*); the driver recomputes older ids from each case's params_json, renames the run
-- folders and records 2 here (driver/case_id_migration.cpp).
CREATE TABLE meta (
  key   TEXT PRIMARY KEY,
  value TEXT NOT NULL
);

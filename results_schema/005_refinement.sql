-- Schema version 5: the points a study's [refine] added to its curves (driver/run/refine_rounds.cpp).
-- An added point is an ordinary case (cases, study_cases, case_values); this row says why it is
-- there: its curve (study, group, setting), its round on that curve, the value of the refined key
-- and the rule's reason (the estimate it rested on and why this value). (study, group, setting,
-- round) is the key: a second driver on the same database that chooses the same round reads the
-- first's point instead of adding another, and a resumed study re-adds the points recorded here.
CREATE TABLE refined_points (
  study      TEXT NOT NULL REFERENCES studies(name),
  group_name TEXT NOT NULL,
  setting    TEXT NOT NULL,     -- the curve within its group: its other swept values; '' for the one curve
  round      INTEGER NOT NULL,  -- 0, 1, ... on that curve
  case_id    TEXT NOT NULL REFERENCES cases(id),
  key        TEXT NOT NULL,     -- the refined key, gravity.angle_deg
  value      REAL NOT NULL,     -- its value at the point
  reason     TEXT NOT NULL,
  added_at   TEXT NOT NULL,
  PRIMARY KEY (study, group_name, setting, round)
);

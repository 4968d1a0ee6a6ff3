-- Schema version 2: remember where each attempt ran (its folder holds the solver log and the
-- checkpoints), and index attempts by case for `study status` on large databases.
ALTER TABLE attempts ADD COLUMN run_dir TEXT;
CREATE INDEX attempts_by_case ON attempts(case_id);

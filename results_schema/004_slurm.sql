-- Schema version 4: attempts run as Slurm array tasks (`boycott study submit`). `study submit`
-- opens one attempt per case with its array job and task; the task records each attempt in its run
-- folder (attempts/<file>.json) and `boycott study collect` copies it here, one row per file, so
-- that a requeued task's attempts are rows of their own. NULL for attempts of `study run`.
ALTER TABLE attempts ADD COLUMN slurm_array_job_id INTEGER;   -- SLURM_ARRAY_JOB_ID (sbatch's job id)
ALTER TABLE attempts ADD COLUMN slurm_array_task_id INTEGER;  -- SLURM_ARRAY_TASK_ID: line of the tasks file
ALTER TABLE attempts ADD COLUMN slurm_job_id INTEGER;         -- SLURM_JOB_ID of the task (NULL until it starts)
ALTER TABLE attempts ADD COLUMN slurm_restart INTEGER;        -- SLURM_RESTART_COUNT: 0, then 1 per requeue
ALTER TABLE attempts ADD COLUMN attempt_file TEXT;            -- the run folder's record collected into this row
CREATE UNIQUE INDEX attempts_by_file ON attempts(case_id, attempt_file) WHERE attempt_file IS NOT NULL;
CREATE INDEX attempts_by_slurm_task ON attempts(slurm_array_job_id, slurm_array_task_id)
  WHERE slurm_array_job_id IS NOT NULL;

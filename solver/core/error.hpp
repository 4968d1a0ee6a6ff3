#pragma once
// Error kinds map to the process exit codes (README.md, "Running a case"), so a driver can tell
// bad input (never retried) from a run that went unstable (retry may help after a change).
#include <stdexcept>
#include <string>
#include <utility>

namespace boycott {

enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,          ///< unexpected internal failure
  kExitInputError = 2,       ///< the case or study file is wrong; nothing ran
  kExitPhysicsError = 3,     ///< the run became unphysical (NaN, alpha_f outside (0,1], ...)
  kExitCheckpointError = 4,  ///< a checkpoint or run folder exists but cannot be used (corrupt, other case)
  kExitStorageError =
      74,  ///< a write failed (disk full, I/O error); the last good checkpoint is kept (EX_IOERR)
  kExitInterrupted = 75,  ///< stopped by SIGINT/SIGTERM after writing a checkpoint (EX_TEMPFAIL)
};

/// Bad input: names the field, the value and the limit. `key()` is the case key at fault where
/// there is one, so that a caller holding the file can add the line that sets it.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  InputError(const std::string& what, std::string key) : std::runtime_error(what), key_(std::move(key)) {}
  const std::string& key() const { return key_; }

 private:
  std::string key_;
};

/// A run that left the physically admissible state; raised before anything is checkpointed.
class PhysicsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A checkpoint that cannot be resumed from.
class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A write that failed for a reason of the storage (disk full, I/O error), not of the data: the
/// same run succeeds once there is room again.
class StorageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The exit code that names an error's kind (kExitFailure for any other exception).
inline int exit_code_of(const std::exception& e) {
  if (dynamic_cast<const InputError*>(&e)) return kExitInputError;
  if (dynamic_cast<const PhysicsError*>(&e)) return kExitPhysicsError;
  if (dynamic_cast<const CheckpointError*>(&e)) return kExitCheckpointError;
  if (dynamic_cast<const StorageError*>(&e)) return kExitStorageError;
  return kExitFailure;
}

}  // namespace boycott

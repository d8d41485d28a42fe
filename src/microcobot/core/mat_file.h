#pragma once
/// @file
/// MATLAB .mat files through matio (Debian libmatio-dev): named real double arrays out, and in
/// with their shape and values checked. Written as MAT 5 (MATLAB's `-v6`/`-v7` container without
/// compression): MATLAB, Octave and scipy.io.loadmat read it, unlike v7.3 (HDF5), which scipy
/// cannot; a variable of MAT 5 holds up to 2^31 bytes, far above the CLI's budget of 2e7 recorded
/// samples (docs/cli.md, "Limits"). Reading accepts MAT 4, 5 and 7.3 (matio with HDF5).
///
/// Errors are one line: mc::InvalidInput "<file>: variable 'x': expected ...".

#include <filesystem>
#include <string>
#include <vector>

#include "microcobot/core/csv.h"

namespace mc {

/// A named real double matrix, column-major (MATLAB's layout): element (r, c) at data[r + c * rows].
struct MatArray {
  std::string name;
  std::size_t rows = 0, cols = 0;
  std::vector<double> data;

  /// An N x 1 column vector.
  static MatArray column(std::string name, std::vector<double> values);
  /// A 1 x 1 scalar.
  static MatArray scalar(std::string name, double value);
};

/// Writes `variables` to `file` as MAT 5, atomically (temporary file in the same directory, then
/// rename). Throws InvalidInput for a name that is not a MATLAB identifier (letter, then letters,
/// digits or '_', at most 63), a duplicate name, a size that does not match rows x cols, or when
/// the file cannot be written.
void write_mat(const std::filesystem::path& file, const std::vector<MatArray>& variables);
/// Every column of `table` as an N x 1 variable of the same name.
void write_mat(const std::filesystem::path& file, const CsvTable& table);

/// Reads every real double (or other real numeric class, converted) 2-D variable of `file`.
/// Throws InvalidInput "<file>: ..." when the file is not a .mat file, or a variable is complex,
/// sparse, a cell or struct, or has more than 2 dimensions.
std::vector<MatArray> read_mat(const std::filesystem::path& file);

/// The variables `names` of `file`, each a vector (1 x N or N x 1) of finite values, all of the same
/// length (at least `min_length`), as the columns of a table named `columns` (same order; `names`
/// when empty). Throws InvalidInput "<file>: variable 'u': missing (have: t, x)", "... expected a
/// vector, got 3x4", "... non-finite value nan at index 17", "... length 10, expected 12 (as 't')".
CsvTable read_mat_columns(const std::filesystem::path& file, const std::vector<std::string>& names,
                          const std::vector<std::string>& columns = {}, std::size_t min_length = 1);

/// True when `file` ends in ".mat" (case-insensitive).
bool is_mat_file(const std::filesystem::path& file);

/// The columns `names` of a CSV file, or the variables of the same names of a .mat file
/// (read_mat_columns), as a table: how the CLI's data commands take either format.
CsvTable read_columns(const std::filesystem::path& file, const std::vector<std::string>& names);

}  // namespace mc

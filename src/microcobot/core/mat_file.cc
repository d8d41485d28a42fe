#include "microcobot/core/mat_file.h"

#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <sstream>
#include <system_error>

#include <matio.h>

#include "microcobot/core/error.h"

namespace mc {
namespace {

/// matio logs to stderr by default; our errors are the exceptions below, one line each.
void quiet_log(int, char*) {}
void init_matio_log() {
  static const bool done = [] {
    Mat_LogInitFunc("microcobot", &quiet_log);
    return true;
  }();
  (void)done;
}

struct MatCloser {
  void operator()(mat_t* m) const { Mat_Close(m); }
};
struct VarFreer {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using MatPtr = std::unique_ptr<mat_t, MatCloser>;
using VarPtr = std::unique_ptr<matvar_t, VarFreer>;

bool is_identifier(const std::string& s) {
  if (s.empty() || s.size() > 63 || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

std::string shape(const matvar_t& v) {
  std::string s;
  for (int i = 0; i < v.rank; ++i) s += (i ? "x" : "") + std::to_string(v.dims[i]);
  return s;
}

template <class T>
void convert(const void* data, std::size_t n, std::vector<double>& out) {
  const T* p = static_cast<const T*>(data);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<double>(p[i]);
}

/// The values of a real numeric 2-D variable as doubles (column-major).
MatArray to_array(const std::string& file, const matvar_t& v) {
  const std::string what = "variable '" + std::string(v.name ? v.name : "?") + "': ";
  if (v.isComplex) throw InvalidInput(file, 0, what + "expected real values, got complex");
  if (v.rank != 2) throw InvalidInput(file, 0, what + "expected a 2-D array, got " + shape(v));
  MatArray a;
  a.name = v.name ? v.name : "";
  a.rows = v.dims[0];
  a.cols = v.dims[1];
  const std::size_t n = a.rows * a.cols;
  a.data.resize(n);
  if (n == 0) return a;
  if (v.data == nullptr) throw InvalidInput(file, 0, what + "no data");
  switch (v.class_type) {
    case MAT_C_DOUBLE:
      convert<double>(v.data, n, a.data);
      break;
    case MAT_C_SINGLE:
      convert<float>(v.data, n, a.data);
      break;
    case MAT_C_INT8:
      convert<std::int8_t>(v.data, n, a.data);
      break;
    case MAT_C_UINT8:
      convert<std::uint8_t>(v.data, n, a.data);
      break;
    case MAT_C_INT16:
      convert<std::int16_t>(v.data, n, a.data);
      break;
    case MAT_C_UINT16:
      convert<std::uint16_t>(v.data, n, a.data);
      break;
    case MAT_C_INT32:
      convert<std::int32_t>(v.data, n, a.data);
      break;
    case MAT_C_UINT32:
      convert<std::uint32_t>(v.data, n, a.data);
      break;
    case MAT_C_INT64:
      convert<std::int64_t>(v.data, n, a.data);
      break;
    case MAT_C_UINT64:
      convert<std::uint64_t>(v.data, n, a.data);
      break;
    default:
      throw InvalidInput(
          file, 0, what + "expected a numeric array (double), got a cell, struct, char or sparse array");
  }
  return a;
}

MatPtr open_for_reading(const std::filesystem::path& file) {
  init_matio_log();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw InvalidInput(file.string(), 0, "no such file");
  if (!std::filesystem::is_regular_file(file, ec))
    throw InvalidInput(file.string(), 0, "not a regular file (a directory, device or FIFO)");
  // The same cap as a CSV file (docs/cli.md, "Input files").
  if (std::filesystem::file_size(file, ec) > (std::uintmax_t{512} << 20)) {
    throw InvalidInput(file.string(), 0, "file larger than 512 MiB");
  }
  MatPtr mat(Mat_Open(file.c_str(), MAT_ACC_RDONLY));
  if (!mat) throw InvalidInput(file.string(), 0, "not a MATLAB .mat file (or unreadable)");
  return mat;
}

std::vector<std::string> variable_names(mat_t* mat) {
  std::vector<std::string> names;
  Mat_Rewind(mat);
  while (matvar_t* info = Mat_VarReadNextInfo(mat)) {
    VarPtr guard(info);
    if (info->name) names.emplace_back(info->name);
  }
  return names;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

}  // namespace

MatArray MatArray::column(std::string name, std::vector<double> values) {
  MatArray a;
  a.name = std::move(name);
  a.rows = values.size();
  a.cols = 1;
  a.data = std::move(values);
  return a;
}

MatArray MatArray::scalar(std::string name, double value) { return {std::move(name), 1, 1, {value}}; }

void write_mat(const std::filesystem::path& file, const std::vector<MatArray>& variables) {
  init_matio_log();
  std::vector<std::string> seen;
  for (const auto& v : variables) {
    if (!is_identifier(v.name)) {
      throw InvalidInput(file.string(), 0, "variable name '" + v.name + "' is not a MATLAB identifier");
    }
    if (std::find(seen.begin(), seen.end(), v.name) != seen.end()) {
      throw InvalidInput(file.string(), 0, "variable '" + v.name + "' written twice");
    }
    seen.push_back(v.name);
    if (v.rows * v.cols != v.data.size()) {
      throw InvalidInput(file.string(), 0,
                         "variable '" + v.name + "': " + std::to_string(v.data.size()) + " values for a " +
                             std::to_string(v.rows) + "x" + std::to_string(v.cols) + " array");
    }
  }
  const std::filesystem::path tmp = file.string() + ".tmp" + std::to_string(::getpid());
  std::filesystem::remove(tmp);
  {
    MatPtr mat(Mat_CreateVer(tmp.c_str(), "MATLAB 5.0 MAT-file, written by microcobot", MAT_FT_MAT5));
    if (!mat) throw InvalidInput(file.string(), 0, "cannot create the file");
    for (const auto& v : variables) {
      std::size_t dims[2] = {v.rows, v.cols};
      VarPtr var(Mat_VarCreate(v.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                               const_cast<double*>(v.data.data()), MAT_F_DONT_COPY_DATA));
      if (!var || Mat_VarWrite(mat.get(), var.get(), MAT_COMPRESSION_NONE) != 0) {
        mat.reset();
        std::filesystem::remove(tmp);
        throw InvalidInput(file.string(), 0, "cannot write variable '" + v.name + "'");
      }
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw InvalidInput(file.string(), 0, "cannot write the file: " + ec.message());
  }
}

void write_mat(const std::filesystem::path& file, const CsvTable& table) {
  std::vector<MatArray> vars;
  for (std::size_t i = 0; i < table.cols(); ++i)
    vars.push_back(MatArray::column(table.names()[i], table.column(i)));
  write_mat(file, vars);
}

std::vector<MatArray> read_mat(const std::filesystem::path& file) {
  MatPtr mat = open_for_reading(file);
  std::vector<MatArray> out;
  for (const auto& name : variable_names(mat.get())) {
    VarPtr v(Mat_VarRead(mat.get(), name.c_str()));
    if (!v) throw InvalidInput(file.string(), 0, "variable '" + name + "': unreadable");
    out.push_back(to_array(file.string(), *v));
  }
  return out;
}

CsvTable read_mat_columns(const std::filesystem::path& file, const std::vector<std::string>& names,
                          const std::vector<std::string>& columns, std::size_t min_length) {
  MatPtr mat = open_for_reading(file);
  const std::string f = file.string();
  CsvTable table;
  table.set_source(f);
  std::size_t length = 0;
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::string& name = names[k];
    const std::string what = "variable '" + name + "': ";
    VarPtr v(Mat_VarRead(mat.get(), name.c_str()));
    if (!v) throw InvalidInput(f, 0, what + "missing (have: " + join(variable_names(mat.get())) + ")");
    MatArray a = to_array(f, *v);
    if (a.rows != 1 && a.cols != 1) {
      throw InvalidInput(f, 0, what + "expected a vector (1xN or Nx1), got " + shape(*v));
    }
    if (a.data.size() < min_length) {
      throw InvalidInput(f, 0,
                         what + "expected at least " + std::to_string(min_length) + " values, got " +
                             std::to_string(a.data.size()));
    }
    for (std::size_t i = 0; i < a.data.size(); ++i) {
      if (!std::isfinite(a.data[i])) {
        std::ostringstream os;
        os << what << "non-finite value " << a.data[i] << " at index " << i;
        throw InvalidInput(f, 0, os.str());
      }
    }
    if (k == 0) {
      length = a.data.size();
    } else if (a.data.size() != length) {
      throw InvalidInput(f, 0,
                         what + "length " + std::to_string(a.data.size()) + ", expected " +
                             std::to_string(length) + " (as '" + names[0] + "')");
    }
    table.add_column(columns.empty() ? name : columns.at(k), std::move(a.data));
  }
  return table;
}

bool is_mat_file(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".mat";
}

CsvTable read_columns(const std::filesystem::path& file, const std::vector<std::string>& names) {
  if (is_mat_file(file)) return read_mat_columns(file, names);
  CsvTable t = read_csv(file);
  for (const auto& n : names) t.column(n);  // a missing column is named here
  return t;
}

}  // namespace mc

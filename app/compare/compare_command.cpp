#include "app/compare/compare_command.hpp"

#include <filesystem>
#include <set>
#include <sstream>
#include <system_error>

#include "app/compare/image_pairs.hpp"
#include "app/run/output_dir.hpp"
#include "render/image.hpp"
#include "render/image_compare.hpp"
#include "render/png_io.hpp"

namespace vdmsim {

namespace fs = std::filesystem;

namespace {

// "largest channel difference 200, 1 of 76800 pixels (share 1.302e-05) over --max-diff 2, more than --max-share 0"
std::string describe(const render::CompareResult& r, const CompareOptions& o, long pixels) {
  std::ostringstream s;
  s.precision(4);
  s << "largest channel difference " << r.largest_diff << ", " << r.differing_pixels << " of " << pixels
    << " pixels (share " << r.differing_share << ") over --max-diff " << o.max_diff << ", "
    << (r.match ? "within" : "more than") << " --max-share " << o.max_share;
  return s.str();
}

bool read(const std::string& path, render::Image& image, std::ostream& err) {
  std::string error;
  if (render::read_png(path, image, error)) return true;
  err << "vdmsim: error: " << error << "\n";
  return false;
}

bool write_diff(const fs::path& path, const render::Image& diff, std::ostream& err) {
  std::error_code ec;
  if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
  std::string error;
  if (!ec && render::write_png(path.string(), diff, 1, false, error)) return true;
  err << "vdmsim: error: " << (ec ? path.string() + ": cannot make its folder (" + ec.message() + ")" : error)
      << "\n";
  return false;
}

// The images compared are the user's references: a --diff that is, or lies inside, EXPECTED
// or ACTUAL would replace or mix with them. Why it does, or "".
std::string diff_overwrites_input(const std::string& expected, const std::string& actual, const std::string& diff) {
  if (diff.empty()) return "";
  for (const std::string& input : {expected, actual})
    if (is_or_lies_inside(diff, input))
      return std::string(fs::is_directory(input) ? "is, or lies inside, " : "is ") + (input == expected ? "EXPECTED " : "ACTUAL ") +
             input + ": the diff images would overwrite or mix with the images compared; choose a path outside both";
  return "";
}

// With two folders, a diff folder that holds an input (--diff naming a parent of EXPECTED) could
// still put a diff image where an input image is: why, naming the first, or "".
std::string diff_image_overwrites_input(const std::string& expected, const std::string& actual,
                                        const ImagePairing& pairing, const std::string& diff) {
  if (diff.empty() || !pairing.folders || !(is_or_lies_inside(expected, diff) || is_or_lies_inside(actual, diff)))
    return "";
  std::error_code ec;
  std::set<fs::path> inputs;
  for (const ImagePair& pair : pairing.pairs)
    for (const std::string& input : {pair.expected, pair.actual}) inputs.insert(fs::weakly_canonical(input, ec));
  for (const ImagePair& pair : pairing.pairs)
    if (const fs::path target = fs::weakly_canonical(fs::path(diff) / pair.name, ec); inputs.count(target))
      return "the diff image of " + pair.name + " would overwrite the compared image " + target.string() +
             "; choose a folder outside both";
  return "";
}

}  // namespace

int cmd_compare(const std::string& expected, const std::string& actual, const CompareOptions& options,
                std::ostream& out, std::ostream& err) {
  if (options.max_diff < 0 || options.max_diff > 255) {
    err << "vdmsim: error: --max-diff " << options.max_diff << ": expected 0 to 255\n";
    return 2;
  }
  if (!(options.max_share >= 0.0 && options.max_share <= 1.0)) {
    err << "vdmsim: error: --max-share " << options.max_share << ": expected a share from 0 to 1\n";
    return 2;
  }
  if (const std::string why = diff_overwrites_input(expected, actual, options.diff); !why.empty()) {
    err << "vdmsim: error: --diff " << options.diff << ": " << why << "\n";
    return 2;
  }
  const ImagePairing pairing = pair_images(expected, actual);
  if (!pairing.ok()) {
    err << "vdmsim: error: " << pairing.error << "\n";
    return 2;
  }
  if (const std::string why = diff_image_overwrites_input(expected, actual, pairing, options.diff); !why.empty()) {
    err << "vdmsim: error: --diff " << options.diff << ": " << why << "\n";
    return 2;
  }

  if (pairing.folders && !options.diff.empty()) {
    std::error_code ec;
    fs::create_directories(options.diff, ec);
    if (ec || !fs::is_directory(options.diff)) {
      err << "vdmsim: error: " << options.diff << ": cannot make the folder for the diff images"
          << (ec ? " (" + ec.message() + ")" : std::string(" (a file of that name exists)")) << "\n";
      return 2;
    }
  }

  const render::CompareTolerance tolerance{options.max_diff, options.max_share};
  int beyond = 0, not_compared = 0, diffs = 0, diff_errors = 0;
  for (const ImagePair& pair : pairing.pairs) {
    render::Image e, a;
    const bool read_e = read(pair.expected, e, err), read_a = read(pair.actual, a, err);
    if (!read_e || !read_a) {
      ++not_compared;
      continue;
    }
    if (e.width != a.width || e.height != a.height) {
      err << "vdmsim: error: " << pair.actual << ": " << a.width << "x" << a.height << " pixels, but " << pair.expected
          << " is " << e.width << "x" << e.height << "\n";
      ++not_compared;
      continue;
    }
    render::Image diff;
    const render::CompareResult r = render::compare_images(e, a, tolerance, options.diff.empty() ? nullptr : &diff);
    if (!r.match) ++beyond;
    if (!r.match || !pairing.folders)
      out << pair.name << ": " << (r.match ? "within" : "beyond") << " tolerance: "
          << describe(r, options, long(e.width) * e.height) << "\n";
    if (!options.diff.empty()) {
      const fs::path path = pairing.folders ? fs::path(options.diff) / pair.name : fs::path(options.diff);
      if (write_diff(path, diff, err)) {
        ++diffs;
        if (!pairing.folders) out << "diff image: " << path.string() << "\n";
      } else {
        ++diff_errors;
      }
    }
  }
  for (const std::string& name : pairing.missing_in_actual) out << name << ": missing in " << actual << "\n";
  for (const std::string& name : pairing.missing_in_expected)
    out << name << ": missing in " << expected << " (found only in " << actual << ")\n";

  const size_t missing = pairing.missing_in_actual.size() + pairing.missing_in_expected.size();
  if (pairing.folders) {
    out << expected << " vs " << actual << ": " << pairing.pairs.size() << " image pairs, "
        << (pairing.pairs.size() - beyond - not_compared) << " within tolerance, " << beyond << " beyond";
    if (not_compared) out << ", " << not_compared << " not compared (errors above)";
    if (missing) out << "; " << missing << " found in one folder only";
    out << "\n";
    if (diffs) out << "diff images: " << diffs << " in " << options.diff << "\n";
    if (diff_errors) out << "diff images not written: " << diff_errors << " (errors above)\n";
  }
  if (not_compared || diff_errors) return 2;
  return beyond || missing ? 1 : 0;
}

}  // namespace vdmsim

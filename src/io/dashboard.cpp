#include "mlmap/io/dashboard.hpp"

#include <system_error>

#include "file_bytes.hpp"
#include "mlmap/error.hpp"

namespace mlmap::io {

void writeDashboard(const std::filesystem::path& directory, const std::filesystem::path& page,
                    const std::string& planes_json) {
  const std::string page_bytes = readWholeFile(page);
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw Error(directory.string() + ": cannot create the directory: " + error.message());
  // Data first, page last: a page never appears beside data it cannot show.
  writeWholeFile(directory / "planes.json", planes_json);
  writeWholeFile(directory / "planes.js", "window.MLMAP_PLANES = " + planes_json + ";\n");
  writeWholeFile(directory / "index.html", page_bytes);
}

}  // namespace mlmap::io

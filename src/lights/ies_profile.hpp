// IES photometric files (ANSI/IESNA LM-63): the parser, and the luminous intensity they
// describe in every direction.
//
// Accepted: LM-63-1995 ("IESNA:LM-63-1995") and LM-63-2002 ("IESNA:LM-63-2002"), and files of
// the same layout: LM-63-1991 ("IESNA91"), LM-63-2019 ("IES:LM-63-2019") and LM-63-1986 (no
// version line). Keyword lines ([TEST], [MANUFAC], ...) are skipped up to the TILT= line.
// TILT=NONE, and TILT=INCLUDE (its lamp-to-luminaire geometry, angles and multiplying factors
// are read and checked, not applied: the luminaire is rendered as photometered); TILT=<file>
// is refused. Then, separated by spaces, commas or line ends:
//   lamps, lumens per lamp (-1: absolute photometry), candela multiplier, number of vertical
//   angles, number of horizontal angles, photometric type, units type, width, length, height,
//   ballast factor, ballast-lamp photometric factor (1995; "future use" in 2002), input watts,
//   the vertical angles, the horizontal angles, and the candela values, all vertical angles of
//   the first horizontal angle first.
// Only type C photometry (photometric type 1) is accepted. Vertical angles increase within
// [0, 180] (0 is the nadir); horizontal angles increase from 0 and end at 0 (rotationally
// symmetric), 90 (symmetric in each quadrant), 180 (symmetric about the 0-180 plane) or 360
// (none), or run from 90 to 270 (symmetric about the 90-270 plane). The candela of a direction
// is value * multiplier * ballast factor (* the ballast-lamp factor for files before 2002).
//
// Every error is an IesError "FILE:LINE: problem" (or "FILE: problem" for the whole file).
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/distribution.hpp"
#include "core/vec.hpp"

namespace pathlab {

struct IesError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A file's contents as written.
struct IesProfile {
    std::string version;  // "LM-63-2002", "LM-63-1995", "LM-63-1991", "LM-63-2019" or "LM-63-1986"
    std::string tilt;     // "NONE" or "INCLUDE"
    int lamps = 1;
    double lumens_per_lamp = -1, multiplier = 1;
    int photometric_type = 1, units_type = 2;
    double width = 0, length = 0, height = 0;
    double ballast_factor = 1, ballast_lamp_factor = 1, input_watts = 0;
    std::vector<double> vertical, horizontal;  // degrees, as in the file
    std::vector<double> values;                // [h * vertical.size() + v], as in the file

    double value(size_t h, size_t v) const { return values[h * vertical.size() + v]; }
    // The factor from a file value to candela: multiplier * ballast factor (* ballast-lamp factor before 2002).
    double candela_scale() const;
    // The lumens the file states (lamps * lumens per lamp * ballast factors), or nothing for
    // absolute photometry.
    std::optional<double> rated_lumens() const;
};

// Parses the text of a file; `name` appears in messages.
IesProfile parse_ies(const std::string& text, const std::string& name);
// Reads and parses a file (regular files of at most 16 MiB).
IesProfile read_ies_file(const std::string& path);

// The luminous intensity of a profile in every direction of the luminaire's frame: the nadir
// (vertical angle 0) along +z, horizontal angle C from +x towards -y (counter-clockwise seen
// from above the luminaire, i.e. from -z, as LM-63 measures), so that a direction is
//   (sin g cos C, -sin g sin C, cos g).
// Symmetric files are expanded to horizontal angles over the full circle [0, 360]. Candela are
// interpolated bilinearly in (vertical, horizontal) angle between the table's angles, and are 0
// outside the vertical range.
//
// Sampling directions by the profile: a cell of the angular grid with probability proportional
// to (the largest of its 4 corner values, the interpolant's maximum there) x (its solid angle
// dC (cos g0 - cos g1)), then a direction uniformly in solid angle inside it (C uniform, cos g
// uniform): pdfW = P(cell) / (solid angle of the cell). So every direction of non-zero
// intensity has a non-zero density, and I / pdfW never exceeds the sum over the cells of
// (largest corner) x (solid angle).
class IesDistribution {
public:
    explicit IesDistribution(const IesProfile& profile);

    const std::vector<double>& vertical() const { return vertical_; }      // degrees
    const std::vector<double>& horizontal() const { return horizontal_; }  // degrees, 0 ... 360
    // Candela at the grid point (vertical index, horizontal index) of the expanded table.
    float grid_value(size_t h, size_t v) const { return candela_[h * vertical_.size() + v]; }

    // Candela in direction (vertical angle g, horizontal angle C), in degrees (C any real).
    float candela(double g, double c) const;
    // Candela in a unit direction of the luminaire's frame.
    float candela(const Vec3f& local) const;
    static Vec3f direction(double g_degrees, double c_degrees);
    static void angles(const Vec3f& local, double& g_degrees, double& c_degrees);

    // A unit direction of the luminaire's frame with its density per unit solid angle.
    std::optional<Vec3f> sample(Vec2f u, float& pdfW) const;
    float pdf(const Vec3f& local) const;
    // Luminous flux, lm: the exact integral of the interpolated candela over the sphere.
    double flux() const { return flux_; }

private:
    size_t cell_index(double g, double c, bool& inside) const;
    std::vector<double> vertical_, horizontal_;
    std::vector<float> candela_;  // [h * vertical_.size() + v]
    std::vector<float> cell_solid_angle_;  // [h * (nv - 1) + v]
    Distribution1D cells_;
    double flux_ = 0;
};

}  // namespace pathlab

// OpenImageIO behind a C interface, built as a plugin of its own
// (BUILD/ringside-oiio.so) that runtime/util/rs_oiio_load.c loads the first time
// an image file is read or written.  OpenImageIO and the ~260 libraries it
// brings (codecs of every image format, DICOM, OpenVDB...) cost every
// ringside process about 0.25 s of dynamic linking at start when linked
// in; most processes (every video render, every --help) never touch them.
// Kept to what ringside needs: a reference resize, image files for
// sequences, and float images for image-based lighting.
//
// The plugin calls nothing of the program's: errors come back in an rs_err
// it fills itself (a plain C struct), so it links against OpenImageIO and
// libpng only.  The entry points are rs_oiio_plugin_*; RS_OIIO_PLUGIN_ABI
// (rs_oiio.h) changes whenever one of them does.
extern "C" { /* rs_err.h and rs_img.h are C headers without their own extern "C" */
#include "rs_err.h"
#include "rs_img.h"
}
#include "rs_oiio.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#ifdef RS_HAVE_OIIO
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <png.h>

using namespace OIIO;

/* the loader's rs_fail folds the multi-line messages OpenImageIO gives into one line */
static bool fail(rs_err *err, rs_oiio_error code, const char *what, const std::string &why)
{
    err->code = code;
    std::snprintf(err->msg, sizeof err->msg, "%s: %s", what, why.c_str());
    return false;
}

extern "C" bool rs_oiio_plugin_resize(const uint8_t *rgba, int sw, int sh, float *out, int w, int h, rs_err *err)
{
    ImageSpec in_spec(sw, sh, 4, TypeDesc::UINT8);
    ImageBuf src(in_spec, const_cast<uint8_t *>(rgba));
    ImageSpec out_spec(w, h, 4, TypeDesc::FLOAT);
    ImageBuf dst(out_spec);
    if (!ImageBufAlgo::resize(dst, src))
        return fail(err, RS_OIIO_ERR_RESIZE, "OpenImageIO resize", dst.geterror());
    if (!dst.get_pixels(ROI(0, w, 0, h, 0, 1, 0, 4), TypeDesc::FLOAT, out))
        return fail(err, RS_OIIO_ERR_RESIZE, "OpenImageIO resize", dst.geterror());
    for (size_t i = 0; i < (size_t)w * h * 4; i++)
        out[i] *= 255.0f;
    return true;
}

/* Encodes into memory (an IOVecOutput): OpenImageIO's own file writers do
 * not report every failed write or close (a full disk left a truncated PNG
 * and "success"), so the bytes are written by the loader, which checks each
 * system call. */
extern "C" bool rs_oiio_plugin_encode(const char *ext, int w, int h, const uint8_t *rgba, uint8_t **out, size_t *n,
                                      rs_err *err)
{
    *out = nullptr;
    *n = 0;
    auto o = ImageOutput::create(ext + 1); /* by format name */
    if (!o)
        return fail(err, RS_OIIO_ERR_WRITE, ext, "OpenImageIO cannot write this format: " + OIIO::geterror());
    if (!o->supports("ioproxy"))
        return fail(err, RS_OIIO_ERR_WRITE, ext, "this OpenImageIO cannot write the format to memory");
    ImageSpec spec(w, h, 4, TypeDesc::UINT8);
    if (!std::strcmp(ext, ".exr"))
        spec.set_format(TypeDesc::HALF);
    spec.alpha_channel = 3;
    if (!std::strcmp(ext, ".png")) { /* the level and filter of rs_png_write (rs_img.c says why) */
        spec.attribute("png:compressionLevel", RS_PNG_LEVEL);
        spec.attribute("png:filter", PNG_FILTER_NONE);
    }
    std::vector<unsigned char> buf;
    Filesystem::IOVecOutput vec(buf);
    if (!o->set_ioproxy(&vec) || !o->open(std::string("frame") + ext, spec))
        return fail(err, RS_OIIO_ERR_WRITE, ext, o->geterror());
    bool ok = o->write_image(TypeDesc::UINT8, rgba);
    std::string e = ok ? "" : o->geterror();
    if (!o->close() && ok) {
        ok = false;
        e = o->geterror();
    }
    if (!ok)
        return fail(err, RS_OIIO_ERR_WRITE, ext, e.empty() ? "encoding failed" : e);
    if (buf.empty())
        return fail(err, RS_OIIO_ERR_WRITE, ext, "OpenImageIO encoded no bytes");
    *out = static_cast<uint8_t *>(std::malloc(buf.size()));
    if (!*out)
        return fail(err, RS_OIIO_ERR_MEMORY, ext, "out of memory");
    std::memcpy(*out, buf.data(), buf.size());
    *n = buf.size();
    return true;
}

extern "C" bool rs_oiio_plugin_read_float(const char *path, int *w, int *h, float **rgb, rs_err *err)
{
    *rgb = nullptr;
    auto in = ImageInput::open(path);
    if (!in)
        return fail(err, RS_OIIO_ERR_READ, path, "cannot read image: " + OIIO::geterror());
    const ImageSpec &spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1)
        return fail(err, RS_OIIO_ERR_FORMAT, path, "not a 2-D image (" + std::to_string(spec.width) + "x" +
                                         std::to_string(spec.height) + ", " + std::to_string(spec.nchannels) +
                                         " channels)");
    if (spec.width > RS_OIIO_MAX_SIDE || spec.height > RS_OIIO_MAX_SIDE)
        return fail(err, RS_OIIO_ERR_FORMAT, path, std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                         " is larger than " + std::to_string(RS_OIIO_MAX_SIDE) + "x" +
                                         std::to_string(RS_OIIO_MAX_SIDE));
    size_t npix = (size_t)spec.width * (size_t)spec.height;
    float *p = (float *)std::malloc(npix * 3 * sizeof(float));
    if (!p)
        return fail(err, RS_OIIO_ERR_MEMORY, path, "out of memory for " + std::to_string(spec.width) + "x" +
                                         std::to_string(spec.height) + " RGB floats");
    int nch = spec.nchannels >= 3 ? 3 : 1;
    /* x stride of three floats: a grey image lands in the first of each triple */
    if (!in->read_image(0, 0, 0, nch, TypeDesc::FLOAT, p, 3 * sizeof(float))) {
        std::string e = in->geterror();
        std::free(p);
        return fail(err, RS_OIIO_ERR_READ, path, e.empty() ? "read failed" : e);
    }
    if (nch == 1)
        for (size_t k = 0; k < npix; k++)
            p[3 * k + 1] = p[3 * k + 2] = p[3 * k];
    in->close();
    *w = spec.width;
    *h = spec.height;
    *rgb = p;
    return true;
}

extern "C" int rs_oiio_plugin_abi(void)
{
    return RS_OIIO_PLUGIN_ABI;
}

extern "C" const char *rs_oiio_plugin_version(void)
{
    static char v[64];
    std::snprintf(v, sizeof v, "OpenImageIO %s", OIIO_VERSION_STRING);
    return v;
}

#endif

// TGX on QEMU mps2-an386 (Cortex-M4F): the reference "Suzanne frame" of soft3d, rendered FRAMES
// times (per-frame instruction count = count(FRAMES=2) - count(FRAMES=1)). The two builds differ
// only in the initial value of `g_frames` (.data): their code is byte for byte the same, so the
// per-address counts of the two runs can be subtracted address by address.
//
// Scene (soft3d's src/testing.rs `reference`), mirrored in z for TGX's right-handed (OpenGL)
// convention; the picture and the on-screen winding are unchanged by the mirror:
//   model: Suzanne (suzanne.h, written by ../gen.py), Babylon world = translate(0.001,0.001,0.001) then RotationY(0.5)
//   camera (0,0,-4) -> origin [Babylon]  =  eye (0,0,4) -> origin [TGX]; vertical FOV 0.8 rad,
//   aspect 1, near 0.1, far 100; 240x240 RGB565; uint16_t z-buffer (TGX's default ZBUFFER_t).
//   ambient 0.2 + directional light along (0.5,-0.5,1) [Babylon] = (0.5,-0.5,-1) [TGX], 0.8;
//   Gouraud, textured (perspective-correct, nearest, wrap), back faces culled.
#include <stdint.h>
#include <stddef.h>
#include <math.h>
#include <tgx.h>
#include "suzanne.h"

extern "C" {
void sh_write0(const char *s);
int sh_open_wb(const char *name);
int sh_write(int fd, const void *buf, size_t len);
void sh_close(int fd);
}

#ifndef FRAMES
#define FRAMES 1
#endif

static constexpr int LX = 240, LY = 240;
static constexpr tgx::Shader LOADED = tgx::SHADER_PERSPECTIVE | tgx::SHADER_ZBUFFER | tgx::SHADER_GOURAUD |
                                      tgx::SHADER_TEXTURE | tgx::SHADER_TEXTURE_NEAREST | tgx::SHADER_TEXTURE_WRAP_POW2;

volatile int g_frames = FRAMES;

__attribute__((aligned(8))) static tgx::RGB565 fb[LX * LY];
__attribute__((aligned(8))) static uint16_t zbuf[LX * LY];
static tgx::Image<tgx::RGB565> im(fb, LX, LY);
static tgx::Renderer3D<tgx::RGB565, LOADED, uint16_t> renderer;

static char *utoa10(uint32_t v, char *p)
{
    char tmp[12];
    int n = 0;
    do { tmp[n++] = (char)('0' + v % 10); v /= 10; } while (v);
    while (n) *p++ = tmp[--n];
    return p;
}

static char *puts_(char *p, const char *s) { while (*s) *p++ = *s++; return p; }

// One frame, as soft3d's firmware counts it: colour clear, depth clear, draw.
__attribute__((noinline)) static void draw_frame()
{
    im.fillScreen(tgx::RGB565(0, 0, 0));
    renderer.clearZbuffer();
    renderer.drawMesh(&suzanne, false);
}

int main()
{
    renderer.setViewportSize(LX, LY);
    renderer.setOffset(0, 0);
    renderer.setImage(&im);
    renderer.setZbuffer(zbuf);
    renderer.setPerspective(0.8f * 180.0f / 3.14159265358979f, 1.0f, 0.1f, 100.0f);
    renderer.setLookAt(0, 0, 4, 0, 0, 0, 0, 1, 0);
    renderer.setCulling(1);
    renderer.setShaders(LOADED);
    renderer.setTextureQuality(tgx::SHADER_TEXTURE_NEAREST);
    renderer.setTextureWrappingMode(tgx::SHADER_TEXTURE_WRAP_POW2);
    renderer.setLight(tgx::fVec3(0.5f, -0.5f, -1.0f), tgx::RGBf(1, 1, 1), tgx::RGBf(1, 1, 1), tgx::RGBf(0, 0, 0));
    renderer.setMaterial(tgx::RGBf(1, 1, 1), 0.2f, 0.8f, 0.0f, 16);

    // Babylon (row vectors): p' = (p + t) * Ry(0.5), t = 0.001 on each axis. Mirrored (z -> -z),
    // as a column-vector matrix: x' = c x - s z + tx', y' = y + ty', z' = s x + c z + tz'.
    const float a = 0.5f, c = cosf(a), s = sinf(a);
    const float tx = 0.001f, ty = 0.001f, tz = -0.001f;  // the translation, mirrored
    renderer.setModelMatrix(tgx::fMat4(c, 0, -s, c * tx - s * tz,
                                       0, 1, 0, ty,
                                       s, 0, c, s * tx + c * tz,
                                       0, 0, 0, 1));

    const int frames = g_frames;
    for (int f = 0; f < frames; f++) draw_frame();

    // After the last frame (the same work in both builds): coverage and the picture.
    uint32_t covered = 0, nonblack = 0;
    for (int i = 0; i < LX * LY; i++) {
        covered += (zbuf[i] != 0);
        nonblack += (((const uint16_t *)fb)[i] != 0);
    }
    int fd = sh_open_wb("out/tgx-frame.rgb565");
    if (fd >= 0) {
        sh_write(fd, fb, sizeof(fb));
        sh_close(fd);
    }
    char line[160], *p = line;
    p = puts_(p, "{\"frames\":"); p = utoa10((uint32_t)frames, p);
    p = puts_(p, ",\"covered_z\":"); p = utoa10(covered, p);
    p = puts_(p, ",\"nonblack\":"); p = utoa10(nonblack, p);
    p = puts_(p, ",\"file\":"); p = utoa10(fd >= 0 ? 1 : 0, p);
    p = puts_(p, "}\n");
    *p = 0;
    sh_write0(line);
    return 0;
}

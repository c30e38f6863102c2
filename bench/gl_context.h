/* gl_context.h -- an OpenGL 4.5 core context on Mesa's llvmpipe through EGL
 * surfaceless (EGL_MESA_platform_surfaceless: no window, no display server),
 * for the bench programs that race shadowlab against llvmpipe, and the GL
 * objects they share: shader programs, depth and float render targets,
 * timed draws. LP_NUM_THREADS must be set before gl_context_open. */
#ifndef SL_GL_CONTEXT_H
#define SL_GL_CONTEXT_H
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>
#include <stdbool.h>
#include "core/error.h"

typedef struct GlContext GlContext;

/* Open the context; fails (with the EGL or GL step that failed) when the
 * renderer is not llvmpipe. renderer() is GL_RENDERER's text. */
GlContext *gl_context_open(Error *err);
void gl_context_close(GlContext *gl);
const char *gl_context_renderer(const GlContext *gl);

/* A linked program from vertex and fragment sources; 0 and err on failure. */
GLuint gl_program(const char *vs_src, const char *fs_src, Error *err);

/* A framebuffer with a w x h texture attachment of `internal` format
 * (GL_DEPTH_COMPONENT32F: depth only, draw buffer none; GL_R32F: colour). */
typedef struct GlTarget {
    GLuint fbo, tex;
    int width, height;
} GlTarget;
bool gl_target_init(GlTarget *t, int width, int height, GLenum internal, Error *err);
void gl_target_free(GlTarget *t);

/* Seconds from just before the first GL call of `draw` to glFinish. */
double gl_timed(void (*draw)(void *arg), void *arg);
/* The first GL error since the last call, as text in err; true when none. */
bool gl_check(const char *what, Error *err);

#endif

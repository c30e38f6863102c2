/* gl_context.c -- EGL surfaceless + OpenGL 4.5 core on llvmpipe (gl_context.h). */
#include "gl_context.h"
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/timer.h"

struct GlContext {
    EGLDisplay dpy;
    EGLContext ctx;
    char renderer[256];
};

static bool egl_fail(EGLDisplay dpy, const char *step, Error *err)
{
    if (dpy != EGL_NO_DISPLAY) eglTerminate(dpy);
    return error_set(err, "EGL: %s failed (error 0x%x); is Mesa's EGL installed (bench/deps.sh)?", step,
                     (unsigned)eglGetError());
}

static bool open_display(GlContext *gl, Error *err)
{
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!get_display) return egl_fail(EGL_NO_DISPLAY, "eglGetProcAddress(eglGetPlatformDisplayEXT)", err);
    gl->dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    EGLint major, minor;
    if (gl->dpy == EGL_NO_DISPLAY || !eglInitialize(gl->dpy, &major, &minor))
        return egl_fail(EGL_NO_DISPLAY, "the surfaceless display", err);
    if (!eglBindAPI(EGL_OPENGL_API)) return egl_fail(gl->dpy, "eglBindAPI(EGL_OPENGL_API)", err);
    return true;
}

static bool create_context(GlContext *gl, Error *err)
{
    static const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    /* EGL_KHR_no_config_context and EGL_KHR_surfaceless_context: no config, no surface. */
    gl->ctx = eglCreateContext(gl->dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (gl->ctx == EGL_NO_CONTEXT) return egl_fail(gl->dpy, "eglCreateContext (OpenGL 4.5 core)", err);
    if (!eglMakeCurrent(gl->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->ctx))
        return egl_fail(gl->dpy, "eglMakeCurrent (surfaceless)", err);
    return true;
}

GlContext *gl_context_open(Error *err)
{
    GlContext *gl = calloc(1, sizeof *gl);
    if (!gl) { error_set(err, "out of memory"); return NULL; }
    if (!open_display(gl, err) || !create_context(gl, err)) { free(gl); return NULL; }
    const char *r = (const char *)glGetString(GL_RENDERER);
    snprintf(gl->renderer, sizeof gl->renderer, "%s", r ? r : "unknown");
    if (!strstr(gl->renderer, "llvmpipe")) {
        error_set(err, "GL renderer is '%s', not llvmpipe (unset MESA_LOADER_DRIVER_OVERRIDE / GALLIUM_DRIVER?)",
                  gl->renderer);
        gl_context_close(gl);
        return NULL;
    }
    /* The engine's clip space: 0 <= z <= w, z_ndc = z / w is what a depth texel holds (mat4.h). */
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    return gl;
}

void gl_context_close(GlContext *gl)
{
    if (!gl) return;
    eglMakeCurrent(gl->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(gl->dpy, gl->ctx);
    eglTerminate(gl->dpy);
    free(gl);
}

const char *gl_context_renderer(const GlContext *gl) { return gl->renderer; }

static GLuint compile(GLenum kind, const char *src, Error *err)
{
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (ok) return s;
    char log[1024] = "";
    glGetShaderInfoLog(s, sizeof log, NULL, log);
    error_set(err, "GLSL %s shader: %s", kind == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
    glDeleteShader(s);
    return 0;
}

GLuint gl_program(const char *vs_src, const char *fs_src, Error *err)
{
    GLuint vs = compile(GL_VERTEX_SHADER, vs_src, err), fs = vs ? compile(GL_FRAGMENT_SHADER, fs_src, err) : 0;
    if (!fs) { glDeleteShader(vs); return 0; }
    GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (ok) return p;
    char log[1024] = "";
    glGetProgramInfoLog(p, sizeof log, NULL, log);
    error_set(err, "GLSL link: %s", log);
    glDeleteProgram(p);
    return 0;
}

bool gl_target_init(GlTarget *t, int width, int height, GLenum internal, Error *err)
{
    bool depth = internal == GL_DEPTH_COMPONENT32F;
    *t = (GlTarget){0, 0, width, height};
    glGenTextures(1, &t->tex);
    glBindTexture(GL_TEXTURE_2D, t->tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, internal, width, height);
    glGenFramebuffers(1, &t->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, depth ? GL_DEPTH_ATTACHMENT : GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t->tex,
                           0);
    GLenum none = GL_NONE, colour = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, depth ? &none : &colour);
    glReadBuffer(depth ? GL_NONE : GL_COLOR_ATTACHMENT0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        gl_target_free(t);
        return error_set(err, "GL: a %dx%d framebuffer is incomplete", width, height);
    }
    glViewport(0, 0, width, height);
    return gl_check("render target", err);
}

void gl_target_free(GlTarget *t)
{
    if (t->fbo) glDeleteFramebuffers(1, &t->fbo);
    if (t->tex) glDeleteTextures(1, &t->tex);
    *t = (GlTarget){0};
}

double gl_timed(void (*draw)(void *arg), void *arg)
{
    double t0 = timer_now_s();
    draw(arg);
    glFinish();
    return timer_now_s() - t0;
}

bool gl_check(const char *what, Error *err)
{
    GLenum e = glGetError();
    if (e == GL_NO_ERROR) return true;
    while (glGetError() != GL_NO_ERROR) {}
    return error_set(err, "GL error 0x%x in %s", (unsigned)e, what);
}

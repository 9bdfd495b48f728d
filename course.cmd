@echo off
rem Constraint Labs on native Windows: tools\course.py with the Python launcher
rem (py -3) or python. WSL2 or the dev container are the documented ways (README);
rem this is for the native MinGW-w64 build (MSYS2), as ./course is elsewhere.
setlocal
where py >nul 2>nul
if %ERRORLEVEL% equ 0 (
  py -3 "%~dp0tools\course.py" %*
  goto :done
)
where python >nul 2>nul
if %ERRORLEVEL% equ 0 (
  python "%~dp0tools\course.py" %*
  goto :done
)
echo course: no Python 3 found; install it from python.org (with the py launcher), or use WSL2 or the dev container (README) 1>&2
exit /b 2
:done
exit /b %ERRORLEVEL%

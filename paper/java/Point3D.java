package javafx.geometry;
// A stand-in for JavaFX's javafx.geometry.Point3D (same formulas), so that the thesis's solvers run
// without JavaFX (paper/java/compare.sh).
public class Point3D {
    public static final Point3D ZERO = new Point3D(0, 0, 0);
    private final double x, y, z;
    public Point3D(double x, double y, double z) { this.x = x; this.y = y; this.z = z; }
    public double getX() { return x; }
    public double getY() { return y; }
    public double getZ() { return z; }
    public Point3D add(Point3D p) { return new Point3D(x + p.x, y + p.y, z + p.z); }
    public Point3D add(double a, double b, double c) { return new Point3D(x + a, y + b, z + c); }
    public Point3D subtract(Point3D p) { return new Point3D(x - p.x, y - p.y, z - p.z); }
    public Point3D multiply(double f) { return new Point3D(x * f, y * f, z * f); }
    public double dotProduct(Point3D p) { return x * p.x + y * p.y + z * p.z; }
    public double dotProduct(double a, double b, double c) { return x * a + y * b + z * c; }
    public Point3D crossProduct(Point3D p) { return new Point3D(y * p.z - z * p.y, z * p.x - x * p.z, x * p.y - y * p.x); }
    public double distance(Point3D p) { double a = p.x - x, b = p.y - y, c = p.z - z; return Math.sqrt(a * a + b * b + c * c); }
    public double magnitude() { return Math.sqrt(x * x + y * y + z * z); }
    public String toString() { return x + "," + y + "," + z; }
}
